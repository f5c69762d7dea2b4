//! The per-call workspace of the virtual-joint model and the check every per-tick function
//! makes of it.

use nalgebra::{Isometry3, Matrix6, SMatrix, Vector3};

use super::model::{MAX_DOF, MAX_MASSES, MAX_SPRINGS, Model};
use crate::error::TickError;

/// Per-call workspace and the last call's by-products, sized once for any model
/// (fixed capacities, so creating one allocates nothing). Records the dimensions of the model
/// it was made for; every per-tick function refuses a model of other dimensions
/// ([`crate::TickError::ModelMismatch`]).
#[derive(Debug, Clone)]
pub struct Data {
    pub(super) dof: usize,
    pub(super) springs: usize,
    /// Rigid TCP pose of the last call, base frame.
    pub tcp: Isometry3<f64>,
    /// Loaded TCP pose of the last [`crate::vjm::deflection`] pass, base frame (Eq. 8; for the
    /// linearized model the rigid pose moved by the first-order deflection).
    pub tcp_deflected: Isometry3<f64>,
    /// Elastic angles `[alpha, beta, gamma]` \[rad\] of each spring from the last
    /// [`crate::vjm::deflection`] call (Eq. 7), in chain order; entries past
    /// [`Model::spring_count`] are zero.
    pub spring_angles: [Vector3<f64>; MAX_SPRINGS],
    /// Actuated-joint Jacobian `[v; w]` of the rigid TCP \[m/rad or 1, rad/rad\], base frame,
    /// from the last [`crate::vjm::deflection`] or [`crate::vjm::joint_jacobian`] pass;
    /// columns past [`Model::dof`] are zero.
    pub jacobian: SMatrix<f64, 6, MAX_DOF>,
    /// Cartesian compliance of the last [`crate::vjm::compliance`] call.
    pub compliance: Matrix6<f64>,
    // Rigid world frames of the springs, and joint axes and origins (before their motion),
    // of the last pass over the chain.
    pub(crate) spring_frames: [Isometry3<f64>; MAX_SPRINGS],
    pub(crate) joint_axes: [Vector3<f64>; MAX_DOF],
    pub(crate) joint_origins: [Vector3<f64>; MAX_DOF],
    /// Moment on each spring \[N m\] (world axes, about the spring's origin) of the last
    /// [`crate::vjm::deflection`] pass; entries past the spring count are zero.
    pub spring_moments: [Vector3<f64>; MAX_SPRINGS],
    // Inertial force and moment about the world origin of each mass, last loaded call.
    pub(crate) mass_loads: [(Vector3<f64>, Vector3<f64>); MAX_MASSES],
}

impl Data {
    /// A workspace for `model`.
    pub fn new(model: &Model) -> Self {
        Self {
            dof: model.dof,
            springs: model.springs,
            tcp: Isometry3::identity(),
            tcp_deflected: Isometry3::identity(),
            spring_angles: [Vector3::zeros(); MAX_SPRINGS],
            jacobian: SMatrix::zeros(),
            compliance: Matrix6::zeros(),
            spring_frames: [Isometry3::identity(); MAX_SPRINGS],
            joint_axes: [Vector3::zeros(); MAX_DOF],
            joint_origins: [Vector3::zeros(); MAX_DOF],
            spring_moments: [Vector3::zeros(); MAX_SPRINGS],
            mass_loads: [(Vector3::zeros(), Vector3::zeros()); MAX_MASSES],
        }
    }

    /// Whether this workspace was made for a model of `model`'s dimensions.
    pub fn check(&self, model: &Model) -> bool {
        self.dof == model.dof && self.springs == model.springs
    }

    /// The axis line of joint `i` (`q` order) at the joints of the last pass that placed the
    /// joints ([`crate::vjm::joint_jacobian`], [`crate::vjm::deflection`]): a point on it
    /// \[m\] and its unit direction, base frame; `None` past the model's dof.
    pub fn joint_axis(&self, i: usize) -> Option<(Vector3<f64>, Vector3<f64>)> {
        if i >= self.dof {
            return None;
        }
        Some((*self.joint_origins.get(i)?, *self.joint_axes.get(i)?))
    }
}
impl Data {
    /// [`Self::check`] as the status every per-tick function returns.
    pub(crate) fn check_model(&self, model: &Model) -> Result<(), TickError> {
        if self.dof != model.dof {
            return Err(TickError::ModelMismatch {
                what: "dof",
                expected: model.dof,
                got: self.dof,
            });
        }
        if self.springs != model.springs {
            return Err(TickError::ModelMismatch {
                what: "springs",
                expected: model.springs,
                got: self.springs,
            });
        }
        Ok(())
    }
}

/// Validates the workspace and a joint vector against the model.
pub(crate) fn check_q(model: &Model, data: &Data, q: &[f64]) -> Result<(), TickError> {
    data.check_model(model)?;
    if q.len() != model.dof {
        return Err(TickError::WrongLength {
            what: "q",
            expected: model.dof,
            got: q.len(),
        });
    }
    check_joint_range(q)
}

/// Largest |joint position| any per-tick function accepts \[rad or m\]: 1e6 (159,000 turns of
/// a continuous joint, 1,000 km of travel). Past it a joint value is a units or overflow
/// mistake (1e300 rad still gives finite sines), refused rather than computed.
pub const MAX_JOINT_POSITION: f64 = 1.0e6;

/// One pass over the joints: [`TickError::NonFinite`] for NaN or an infinity,
/// [`TickError::InvalidArgument`] for a joint past [`MAX_JOINT_POSITION`].
pub(crate) fn check_joint_range(q: &[f64]) -> Result<(), TickError> {
    match q
        .iter()
        .enumerate()
        .find(|(_, v)| v.is_nan() || v.abs() > MAX_JOINT_POSITION)
    {
        Some((index, v)) if !v.is_finite() => Err(TickError::NonFinite { what: "q", index }),
        Some((_, &value)) => Err(TickError::InvalidArgument {
            what: "q (a joint position past MAX_JOINT_POSITION = 1e6 rad or m)",
            value,
        }),
        None => Ok(()),
    }
}
