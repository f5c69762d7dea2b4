//! Cartesian stiffness of the drive train (Eq. 11-13 of the contour-tracking paper):
//! `K = J^-T K_theta J^-1` for square Jacobians.

use nalgebra::{Matrix2, Matrix3, Matrix6, SMatrix, SVD};

use super::{Data, Model, check_q};
use crate::error::TickError;
use crate::vjm;

macro_rules! square_stiffness {
    ($n:literal, $mat:ty, $rows:expr, $model:expr, $data:expr, $q:expr) => {{
        check_q($model, $data, $q)?;
        if $model.dof() != $n {
            return Err(TickError::WrongLength {
                what: "joints (square Jacobian)",
                expected: $n,
                got: $model.dof(),
            });
        }
        vjm::joint_jacobian($model.chain(), &mut $data.vjm, $q)?;
        let rows: [usize; $n] = $rows;
        let j = <$mat>::from_fn(|r, c| {
            rows.get(r)
                .and_then(|&src| $data.vjm.jacobian.get((src, c)))
                .copied()
                .unwrap_or(0.0)
        });
        let svd =
            SVD::try_new(j, true, true, f64::EPSILON, 100).ok_or(TickError::NotConverged {
                iterations: 100,
                residual: f64::NAN,
            })?;
        let s = &svd.singular_values;
        let (smin, smax) = s
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
        if !(smin > 0.0 && smax / smin <= $model.max_condition) {
            return Err(TickError::Singular {
                what: "joint Jacobian (square)",
                sigma_min: smin,
            });
        }
        let j_inv = svd.pseudo_inverse(0.0).map_err(|_| TickError::Singular {
            what: "joint Jacobian (square)",
            sigma_min: smin,
        })?;
        let k_theta = <$mat>::from_fn(|r, c| {
            if r == c {
                $model.stiffness.get(r).copied().unwrap_or(0.0)
            } else {
                0.0
            }
        });
        let k = j_inv.transpose() * k_theta * j_inv;
        // Symmetrize away the rounding.
        let k = (k + k.transpose()) * 0.5;
        crate::error::check_output("cartesian stiffness", k.as_slice())?;
        Ok(k)
    }};
}

/// Cartesian stiffness `K = J^-T K_theta J^-1` (Eq. 12-13) of a 6-joint arm, 6x6, ordered
/// `[dp; dr] -> [F; M]` like the Jacobian rows `[v; w]` (base frame). Joint compliance only:
/// the links are rigid. [`TickError::Singular`] when the Jacobian's condition number exceeds
/// the model's limit; [`TickError::WrongLength`] unless the model has 6 joints.
pub fn cartesian_stiffness(
    model: &Model,
    data: &mut Data,
    q: &[f64],
) -> Result<Matrix6<f64>, TickError> {
    square_stiffness!(6, Matrix6<f64>, [0, 1, 2, 3, 4, 5], model, data, q)
}

/// Planar xy stiffness of a 2-joint arm moving in the xy plane (Eq. 11-13 for the contour
/// case): the x and y rows of the Jacobian, 2x2 \[N/m\]. Errors as [`cartesian_stiffness`].
pub fn cartesian_stiffness_xy(
    model: &Model,
    data: &mut Data,
    q: &[f64],
) -> Result<Matrix2<f64>, TickError> {
    square_stiffness!(2, Matrix2<f64>, [0, 1], model, data, q)
}

/// Planar stiffness of a 3-joint arm moving in the xy plane: rows x, y and the rotation
/// about z, 3x3, `[dx, dy, rz] -> [Fx, Fy, Mz]`. Errors as [`cartesian_stiffness`].
pub fn cartesian_stiffness_planar(
    model: &Model,
    data: &mut Data,
    q: &[f64],
) -> Result<Matrix3<f64>, TickError> {
    square_stiffness!(3, Matrix3<f64>, [0, 1, 5], model, data, q)
}

/// The xy block of a planar 3x3 stiffness with the moment about z left free (`Mz = 0`): the
/// Schur complement `K_xx - K_xr K_rr^-1 K_rx`, for a probe that transmits no moment.
/// `None` if `K_rr` is not positive.
pub fn free_moment_xy(k: &Matrix3<f64>) -> Option<Matrix2<f64>> {
    let at = |r: usize, c: usize| k.get((r, c)).copied().unwrap_or(f64::NAN);
    let krr = at(2, 2);
    if !(krr > 0.0 && krr.is_finite()) {
        return None;
    }
    let kxr = SMatrix::<f64, 2, 1>::new(at(0, 2), at(1, 2));
    let kxx = Matrix2::new(at(0, 0), at(0, 1), at(1, 0), at(1, 1));
    Some(kxx - kxr * kxr.transpose() / krr)
}
