//! Compensation: the pose or the joint values to command so that the deflected TCP lands on
//! the target (section 2.2 of the VJM paper: Cartesian correction values sent to the robot
//! controller, or axis-specific ones through an inverse kinematics).

use nalgebra::{Isometry3, SVD, SVector, Translation3, UnitQuaternion, Vector3};

use super::data::check_q;
use super::deflection::{deflection, joint_jacobian};
use super::{Data, Load, MAX_DOF, Model, Vector6};
use crate::error::{TickError, check_finite, check_output};

/// Most Gauss-Newton steps a [`joint_correction`] may be asked for: the correction converges
/// in 2-5 steps, so more is a mistake; past it the call refuses with [`TickError::Budget`]
/// (it bounds the call's time: each step costs about 10 us on a 6-axis arm).
pub const MAX_CORRECTION_ITERATIONS: usize = 256;
/// A Gauss-Newton step that lowers the residual by less than this fraction ends the
/// iteration ([`JointCorrection::stalled`]): the least-squares fixed point of an
/// under-actuated arm, or rounding.
const STALL_FRACTION: f64 = 1.0e-9;

/// Largest ratio `sigma_max / sigma_min` of the joint Jacobian at which a joint correction
/// is still computed; beyond it the pose counts as singular.
const MAX_CONDITION: f64 = 1.0e8;
/// Sweeps allowed to nalgebra's SVD: bounds the time of a call. A 6 x 8 matrix converges in
/// well under 20 in practice.
const SVD_MAX_ITERATIONS: usize = 100;

/// The pose to command so that a TCP that deflects by `deflection` (from
/// [`crate::vjm::deflection`] at the target) lands on `target`: translation minus `dp`,
/// rotation turned back by `dr`. First order in the pose dependence of the deflection, exact
/// for the given deflection.
///
/// [`TickError::NonFinite`] for a non-finite input, [`TickError::InvalidArgument`] for a
/// rotation part longer than pi (a rotation vector's angle is at most pi; 1e300 rad would turn
/// into NaN), [`TickError::NonFiniteOutput`] if the pose overflows.
pub fn commanded_pose(
    target: &Isometry3<f64>,
    deflection: &Vector6,
) -> Result<Isometry3<f64>, TickError> {
    check_finite("deflection", deflection.as_slice())?;
    check_finite("target translation", target.translation.vector.as_slice())?;
    check_finite("target rotation", target.rotation.coords.as_slice())?;
    let dp = Vector3::new(deflection[0], deflection[1], deflection[2]);
    let dr = Vector3::new(deflection[3], deflection[4], deflection[5]);
    let angle = dr.norm();
    if angle > core::f64::consts::PI {
        return Err(TickError::InvalidArgument {
            what: "deflection rotation (|dr| rad; a rotation vector's angle is at most pi)",
            value: angle,
        });
    }
    let pose = Isometry3::from_parts(
        Translation3::from(target.translation.vector - dp),
        UnitQuaternion::from_scaled_axis(-dr) * target.rotation,
    );
    check_output("commanded translation", pose.translation.vector.as_slice())?;
    check_output("commanded rotation", pose.rotation.coords.as_slice())?;
    Ok(pose)
}

/// Result of [`joint_correction`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[must_use]
pub struct JointCorrection {
    /// Axis-specific correction `dq` \[rad or m\] to add to the nominal joints; entries past
    /// [`Model::dof`] are zero.
    pub dq: [f64; MAX_DOF],
    /// Gauss-Newton steps taken.
    pub iterations: usize,
    /// Remaining pose error `|[dp; dr]|` \[m, rad\] of the deflected TCP at `q + dq`.
    pub residual: f64,
    /// Smallest singular value of the actuated-joint Jacobian at the last step (NaN if no
    /// step was needed).
    pub sigma_min: f64,
    /// `residual <= tolerance`. An under-actuated robot (fewer than 6 joints) generally
    /// cannot cancel the whole pose error: it gets the least-squares fixed point instead.
    pub converged: bool,
    /// The iteration stopped because a step no longer lowered the residual (by more than a
    /// fraction 1e-9) before reaching `tolerance`: the fixed point, not a failure to try.
    pub stalled: bool,
}

/// Least-squares, minimum-norm `dq` with `J dq = delta` for the Jacobian in `data`
/// (filled by [`joint_jacobian`]); also returns the smallest relevant singular value.
fn solve_jacobian(
    data: &Data,
    dof: usize,
    delta: &Vector6,
) -> Result<(SVector<f64, MAX_DOF>, f64), TickError> {
    let svd = SVD::try_new(data.jacobian, true, true, f64::EPSILON, SVD_MAX_ITERATIONS).ok_or(
        TickError::NotConverged {
            iterations: SVD_MAX_ITERATIONS,
            residual: f64::NAN,
        },
    )?;
    // The `min(dof, 6)` largest singular values span the reachable directions.
    let mut sv = [0.0f64; 6];
    for (dst, &s) in sv.iter_mut().zip(svd.singular_values.iter()) {
        *dst = s;
    }
    sv.sort_unstable_by(|a, b| b.total_cmp(a));
    let rank = dof.min(6);
    let sigma_max = sv.first().copied().unwrap_or(0.0);
    let sigma_min = sv.get(rank.saturating_sub(1)).copied().unwrap_or(0.0);
    if !(sigma_min > 0.0 && sigma_max / sigma_min < MAX_CONDITION) {
        return Err(TickError::Singular {
            what: "joint Jacobian",
            sigma_min,
        });
    }
    let step = svd
        .solve(delta, sigma_max / MAX_CONDITION)
        .map_err(|_| TickError::Singular {
            what: "joint Jacobian",
            sigma_min,
        })?;
    Ok((step, sigma_min))
}

/// Axis-specific values for a Cartesian correction: the least-squares, minimum-norm `dq`
/// \[rad or m\] with `J(q) dq = delta`, `delta = [dp; dr]` \[m, rad\] in the base frame (the
/// paper's conversion of Cartesian correction values into axis values, section 2.2).
/// Entries past [`Model::dof`] are zero. [`TickError::Singular`] near singular poses.
pub fn joint_delta(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    delta: &Vector6,
) -> Result<[f64; MAX_DOF], TickError> {
    check_finite("delta", delta.as_slice())?;
    joint_jacobian(model, data, q)?;
    let (step, _) = solve_jacobian(data, model.dof, delta)?;
    let mut out = [0.0; MAX_DOF];
    for (dst, &v) in out.iter_mut().zip(step.iter()).take(model.dof) {
        *dst = v;
    }
    check_output("dq", &out)?;
    Ok(out)
}

/// A homogeneous 4x4 transform as an isometry, checked rather than repaired: every entry
/// finite, the bottom row `[0, 0, 0, 1]` (within 1e-9), the rotation block orthonormal
/// (`|R^T R - I|` at most 1e-9 per entry) with determinant +1 (a reflection is refused).
/// The quaternion is then computed in closed form, so the call runs in bounded time whatever
/// the input ([`TickError::NonFinite`] or [`TickError::InvalidArgument`] naming the defect).
pub fn pose_from_matrix(m: &nalgebra::Matrix4<f64>) -> Result<Isometry3<f64>, TickError> {
    check_finite("pose", m.as_slice())?;
    let bottom = [m[(3, 0)], m[(3, 1)], m[(3, 2)], m[(3, 3)] - 1.0];
    let off = bottom.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if off > POSE_TOLERANCE {
        return Err(TickError::InvalidArgument {
            what: "pose bottom row (must be 0 0 0 1; largest deviation)",
            value: off,
        });
    }
    let r = m.fixed_view::<3, 3>(0, 0).into_owned();
    let rotation = rotation_from_matrix(&r)?;
    let t = Vector3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
    Ok(Isometry3::from_parts(Translation3::from(t), rotation))
}

/// Largest deviation from an exact rigid transform accepted by [`pose_from_matrix`] and
/// [`rotation_from_matrix`] (per entry of `R^T R - I`, and of the bottom row).
pub const POSE_TOLERANCE: f64 = 1.0e-9;

/// A 3x3 rotation matrix as a unit quaternion, checked: finite, orthonormal within
/// [`POSE_TOLERANCE`], determinant +1. Closed form (no iteration).
pub fn rotation_from_matrix(r: &nalgebra::Matrix3<f64>) -> Result<UnitQuaternion<f64>, TickError> {
    check_finite("rotation", r.as_slice())?;
    let err = (r.transpose() * r - nalgebra::Matrix3::identity())
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    if err > POSE_TOLERANCE {
        return Err(TickError::InvalidArgument {
            what: "rotation (not orthonormal; largest entry of R^T R - I)",
            value: err,
        });
    }
    let det = r.determinant();
    if det < 0.0 {
        return Err(TickError::InvalidArgument {
            what: "rotation (a reflection; determinant)",
            value: det,
        });
    }
    Ok(UnitQuaternion::from_rotation_matrix(
        &nalgebra::Rotation3::from_matrix_unchecked(*r),
    ))
}

/// Axis-specific correction: the `dq` such that the robot commanded to `q + dq` and loaded by
/// `wrench` puts its deflected TCP on the rigid TCP of `q`.
///
/// Each step solves `J dq = -e` in the least-squares, minimum-norm sense through an SVD of
/// the actuated-joint Jacobian (robots with fewer or more than 6 axes work too); with
/// `max_iterations = 1` this is the paper's first-order `dq = -J^+ Delta`. The wrench is held
/// constant in the base frame while the pose changes. Steps stop once the residual is at most
/// `tolerance` \[m, rad\] (finite, >= 0), after `max_iterations` (at most
/// [`MAX_CORRECTION_ITERATIONS`]), or once a step stops lowering the residual;
/// [`JointCorrection::converged`] and [`JointCorrection::stalled`] say which. Returns
/// [`TickError::Singular`] near a singular pose, [`TickError::InvalidArgument`] for a bad
/// tolerance, [`TickError::Budget`] past the iteration limit.
pub fn joint_correction(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    wrench: &Vector6,
    max_iterations: usize,
    tolerance: f64,
) -> Result<JointCorrection, TickError> {
    check_q(model, data, q)?;
    check_finite("wrench", wrench.as_slice())?;
    check_finite("tolerance", &[tolerance])?;
    if tolerance < 0.0 {
        return Err(TickError::InvalidArgument {
            what: "tolerance",
            value: tolerance,
        });
    }
    if max_iterations > MAX_CORRECTION_ITERATIONS {
        return Err(TickError::Budget {
            what: "Gauss-Newton iterations",
            budget: "MAX_CORRECTION_ITERATIONS",
            limit: MAX_CORRECTION_ITERATIONS as f64,
            requested: max_iterations as f64,
        });
    }
    let dof = model.dof;
    let mut qk = [0.0; MAX_DOF];
    for (dst, &src) in qk.iter_mut().zip(q) {
        *dst = src;
    }
    // The target is the rigid TCP at the nominal joints.
    super::forward(model, data, q)?;
    let target = data.tcp;
    let mut out = JointCorrection {
        dq: [0.0; MAX_DOF],
        iterations: 0,
        residual: f64::INFINITY,
        sigma_min: f64::NAN,
        converged: false,
        stalled: false,
    };
    // The best iterate so far: a step that does not improve is not kept.
    let mut best = qk;
    for it in 0..=max_iterations {
        let qcur = qk;
        let qs = qcur.get(..dof).unwrap_or(&[]);
        // The pass leaves the deflected TCP and the Jacobian at `qs` in `data`.
        deflection(model, data, qs, wrench, Load::Exact)?;
        let d = data.tcp_deflected;
        let ep = d.translation.vector - target.translation.vector;
        let er = super::rotation_vector(&(d.rotation * target.rotation.inverse()));
        let e = Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z);
        let residual = e.norm();
        out.iterations = it;
        if it > 0 && (residual.is_nan() || residual >= out.residual * (1.0 - STALL_FRACTION)) {
            out.stalled = residual > tolerance;
            if residual < out.residual {
                (out.residual, best) = (residual, qcur);
            }
            break;
        }
        (out.residual, best) = (residual, qcur);
        if residual <= tolerance || it == max_iterations {
            break;
        }
        let (step, sigma_min) = solve_jacobian(data, dof, &(-e))?;
        out.sigma_min = sigma_min;
        for (qi, si) in qk.iter_mut().zip(step.iter()).take(dof) {
            *qi += si;
        }
    }
    for ((dst, &qi), &q0) in out.dq.iter_mut().zip(best.iter()).zip(q) {
        *dst = qi - q0;
    }
    check_output("dq", &out.dq)?;
    out.converged = out.residual <= tolerance;
    Ok(out)
}
