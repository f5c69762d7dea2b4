//! A serial arm's rigid TCP position as a mechanism: damped-least-squares IK from a seed.

use nalgebra::{ComplexField, Matrix3, SMatrix, SVector, Vector3};

use super::{Mechanism, check_finite, positive};
use crate::error::{BuildError, TickError};
use crate::vjm::{self, Data, Model};

/// Settings of [`SerialArm`]'s damped-least-squares IK.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOptions {
    /// Iteration budget (bounds the time of a call).
    pub max_iterations: usize,
    /// Position tolerance \[m\].
    pub tolerance: f64,
    /// Damping `lambda` of `dq = J^T (J J^T + lambda^2 I)^-1 e` \[m/rad\].
    pub damping: f64,
    /// Largest joint step per iteration (Euclidean norm) \[rad\].
    pub max_step: f64,
    /// Singularity threshold on the smallest singular value of the 3 x J position Jacobian
    /// \[m/rad\].
    pub min_sigma: f64,
}

impl Default for IkOptions {
    /// 50 iterations, 1e-9 m, damping 1e-3 m/rad, steps of at most 0.5 rad, threshold
    /// 1e-4 m/rad.
    fn default() -> Self {
        Self {
            max_iterations: 50,
            tolerance: 1.0e-9,
            damping: 1.0e-3,
            max_step: 0.5,
            min_sigma: 1.0e-4,
        }
    }
}

/// A serial arm ([`crate::vjm::Model`] with exactly `J` joints) as a `Mechanism<3, J>`: the
/// task is the rigid TCP position in the base frame (orientation is left free, so a 6R arm
/// is redundant here and the IK keeps it close to the seed).
///
/// Its workspace is the chain's [`Data`].
#[derive(Debug, Clone)]
pub struct SerialArm<const J: usize> {
    model: Model,
    options: IkOptions,
}

impl<const J: usize> SerialArm<J> {
    /// Wraps `model`; its [`Model::dof`] must be `J`.
    pub fn new(model: Model, options: IkOptions) -> Result<Self, BuildError> {
        if model.dof() != J {
            return Err(BuildError::DofMismatch {
                what: "SerialArm<J>",
                expected: model.dof(),
                got: J,
            });
        }
        positive("tolerance", options.tolerance)?;
        positive("damping", options.damping)?;
        positive("max_step", options.max_step)?;
        positive("min_sigma", options.min_sigma)?;
        Ok(Self { model, options })
    }

    /// The wrapped model.
    pub fn model(&self) -> &Model {
        &self.model
    }
    /// The IK settings.
    pub fn options(&self) -> IkOptions {
        self.options
    }

    fn fk_jac(
        &self,
        data: &mut Data,
        q: &SVector<f64, J>,
    ) -> Result<(Vector3<f64>, SMatrix<f64, 3, J>), TickError> {
        vjm::joint_jacobian(&self.model, data, q.as_slice())?;
        let x = data.tcp.translation.vector;
        let jac =
            SMatrix::<f64, 3, J>::from_fn(|r, c| data.jacobian.get((r, c)).copied().unwrap_or(0.0));
        Ok((x, jac))
    }
}

/// Smallest singular value of a 3 x J matrix via the eigenvalues of `J J^T` (0 if J < 3 or
/// the eigen-solver does not converge).
fn sigma_min3<const J: usize>(jac: &SMatrix<f64, 3, J>) -> f64 {
    let g: Matrix3<f64> = jac * jac.transpose();
    match nalgebra::SymmetricEigen::try_new(g, 1.0e-15, 100) {
        Some(e) => ComplexField::sqrt(e.eigenvalues.min().max(0.0)),
        None => 0.0,
    }
}

impl<const J: usize> Mechanism<3, J> for SerialArm<J> {
    type Data = Data;

    fn new_data(&self) -> Data {
        Data::new(&self.model)
    }

    /// Damped least squares from `seed`: `dq = J^T (J J^T + lambda^2 I)^-1 (x - FK(q))`, the
    /// step clipped to `max_step`, at most `max_iterations` steps. Fails with
    /// [`TickError::Singular`] if the final pose's smallest singular value is below
    /// `min_sigma`, else [`TickError::NotConverged`] if the residual is above
    /// `tolerance` (e.g. a target out of reach).
    fn inverse(
        &self,
        data: &mut Data,
        x: &Vector3<f64>,
        seed: &SVector<f64, J>,
    ) -> Result<SVector<f64, J>, TickError> {
        check_finite("x", x)?;
        check_finite("seed", seed)?;
        let o = self.options;
        let mut q = *seed;
        let lambda2 = o.damping * o.damping;
        let mut iterations = 0;
        loop {
            let (fx, jac) = self.fk_jac(data, &q)?;
            let e = x - fx;
            let residual = e.norm();
            if residual <= o.tolerance || iterations >= o.max_iterations {
                let distance = sigma_min3(&jac);
                if distance < o.min_sigma {
                    return Err(TickError::Singular {
                        what: "task Jacobian",
                        sigma_min: distance,
                    });
                }
                if residual <= o.tolerance {
                    return Ok(q);
                }
                return Err(TickError::NotConverged {
                    iterations,
                    residual,
                });
            }
            let g = jac * jac.transpose() + Matrix3::identity() * lambda2;
            let Some(w) = g.cholesky().map(|c| c.solve(&e)) else {
                return Err(TickError::Singular {
                    what: "task Jacobian",
                    sigma_min: sigma_min3(&jac),
                });
            };
            let mut dq = jac.transpose() * w;
            let n = dq.norm();
            if n > o.max_step {
                dq *= o.max_step / n;
            }
            q += dq;
            iterations += 1;
        }
    }

    fn forward(&self, data: &mut Data, q: &SVector<f64, J>) -> Result<Vector3<f64>, TickError> {
        Ok(vjm::forward(&self.model, data, q.as_slice())?
            .translation
            .vector)
    }

    fn jacobian(
        &self,
        data: &mut Data,
        q: &SVector<f64, J>,
    ) -> Result<SMatrix<f64, 3, J>, TickError> {
        Ok(self.fk_jac(data, q)?.1)
    }

    fn singularity_distance(&self, data: &mut Data, q: &SVector<f64, J>) -> Result<f64, TickError> {
        Ok(sigma_min3(&self.jacobian(data, q)?))
    }
}
