//! Rigid kinematics behind one interface, so that a D'Alembert corrector (desired
//! acceleration -> force -> compliance map -> corrected task point -> IK, section 3.3 of
//! Paksoy, Dede and Kiper 2025) does not care which robot it drives.
//!
//! [`Mechanism<T, J>`] has the task dimension `T` and the joint dimension `J` as const
//! parameters (stable Rust cannot size an `SVector` from an associated const), so every
//! quantity is a fixed-size `nalgebra` type: task points `SVector<f64, T>`, joints
//! `SVector<f64, J>`, Jacobians `SMatrix<f64, T, J>`. Each mechanism has a workspace type
//! ([`Mechanism::Data`], made once by [`Mechanism::new_data`]); nothing allocates or panics;
//! errors are a [`TickError`].
//!
//! Implementations:
//! * [`ParallelRobot2`]: the paper's 2-DoF planar parallel robot, `Mechanism<2, 2>`,
//!   closed-form IK/FK.
//! * [`Delta`]: the 3-DoF Delta robot of Clavel, `Mechanism<3, 3>`, closed-form IK/FK.
//! * [`SerialArm`]: a [`crate::vjm::Model`] (serial arm with `J` joints), `Mechanism<3, J>`:
//!   the task is the rigid TCP position; IK by bounded damped least squares from a seed, in a
//!   [`crate::vjm::Data`] workspace.

mod delta;
pub mod limits;
mod parallel;
pub mod pose_ik;
mod serial;

pub use delta::{DELTA_MAX_LENGTH, DELTA_MIN_LENGTH, DELTA_MIN_SIGMA, Delta};
pub use limits::{JOINT_LIMIT_TOLERANCE, check_limits};
pub use parallel::{DEFAULT_MIN_SIGMA, PAPER_HALF_WIDTH, PAPER_LINK, ParallelRobot2};
pub use pose_ik::{PoseIkOptions, PoseIkSolution, Task, largest_task, pose_ik};
pub use serial::{IkOptions, SerialArm};

use nalgebra::{SMatrix, SVector};

use crate::error::TickError;

/// Rigid kinematics of a robot with `J` joints whose task is a point in `T` dimensions.
///
/// A corrector written against `M: Mechanism<T, J>` gets everything it needs: `inverse` to
/// turn the corrected task point into joint commands (seeded with the previous tick's
/// joints), `forward` and `jacobian` to map back, and `singularity_distance` to refuse
/// commands near a singularity.
pub trait Mechanism<const T: usize, const J: usize> {
    /// Per-call workspace (`()` for closed-form mechanisms, the chain's [`crate::vjm::Data`]
    /// for a serial arm). Made once, outside the tick.
    type Data;

    /// A workspace for this mechanism.
    fn new_data(&self) -> Self::Data;

    /// Joints that put the task point on `x`. Closed-form solvers ignore `seed`; iterative
    /// ones start from it (pass the previous tick's joints).
    fn inverse(
        &self,
        data: &mut Self::Data,
        x: &SVector<f64, T>,
        seed: &SVector<f64, J>,
    ) -> Result<SVector<f64, J>, TickError>;

    /// Task point of joints `q`.
    fn forward(
        &self,
        data: &mut Self::Data,
        q: &SVector<f64, J>,
    ) -> Result<SVector<f64, T>, TickError>;

    /// Task Jacobian `dx/dq` at `q` \[m/rad or m/m\].
    fn jacobian(
        &self,
        data: &mut Self::Data,
        q: &SVector<f64, J>,
    ) -> Result<SMatrix<f64, T, J>, TickError>;

    /// Distance to the nearest singularity: the smallest singular value of [`Self::jacobian`]
    /// at `q` \[m/rad\] (0 at a singularity; the task speed the worst-placed unit joint speed
    /// still produces).
    fn singularity_distance(
        &self,
        data: &mut Self::Data,
        q: &SVector<f64, J>,
    ) -> Result<f64, TickError>;
}

fn check_finite<const D: usize>(what: &'static str, v: &SVector<f64, D>) -> Result<(), TickError> {
    crate::error::check_finite(what, v.as_slice())
}

fn positive(what: &'static str, value: f64) -> Result<f64, crate::BuildError> {
    crate::error::param(what, value, value > 0.0, "finite and > 0")
}
