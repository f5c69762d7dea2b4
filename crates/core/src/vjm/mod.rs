//! Virtual-joint model (VJM) of a serial robot: forward compliance after Hähn & Weigold,
//! "Hybrid compliance compensation for path accuracy enhancement in robot machining",
//! section 2.1, Eq. 1-9 (`shared/papers/001_bf9bba303970c33c.txt`).
//!
//! A [`Model`] is a chain of fixed transforms, actuated revolute/prismatic joints and virtual
//! joints ("springs"): frames with three rotational stiffnesses about their own x, y, z axes
//! (k_C, k_B, k_A of the paper's Table 1). Under a TCP wrench each spring turns by
//! `M / k` about its axes (Eq. 5-7), the turn is inserted as a z-y'-x'' rotation (Eq. 3-4), and
//! the deflected forward kinematics (Eq. 8) minus the rigid one (Eq. 9) is the deflection.

mod correction;
mod deflection;
mod model;

pub use correction::{JointCorrection, commanded_pose, joint_correction, joint_delta};
pub use deflection::{compliance, deflection, forward, joint_jacobian};
pub use model::{Data, Element, MAX_DOF, MAX_ELEMENTS, MAX_SPRINGS, Model, ModelBuilder};

/// A 6-vector `[x, y, z, rx, ry, rz]`: a wrench `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m] or a small
/// pose change `[dx, dy, dz, rx, ry, rz]` [m, rad] (rotation vector), always in the base frame.
pub type Vector6 = nalgebra::Vector6<f64>;
