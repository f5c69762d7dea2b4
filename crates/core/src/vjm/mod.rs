//! Virtual-joint model (VJM) of a serial robot: forward compliance after Hähn & Weigold,
//! "Hybrid compliance compensation for path accuracy enhancement in robot machining",
//! Production Engineering (2020), section 2.1, Eq. 1-9.
//!
//! A [`Model`] is a chain of fixed transforms, actuated revolute/prismatic joints and virtual
//! joints ("springs"): frames with three rotational stiffnesses about their own x, y, z axes
//! (k_C, k_B, k_A of the paper's Table 1). Under a TCP wrench each spring turns by
//! `M / k` about its axes (Eq. 5-7), the turn is inserted as a z-y'-x'' rotation (Eq. 3-4), and
//! the deflected forward kinematics (Eq. 8) minus the rigid one (Eq. 9) is the deflection.
//!
//! One pass per quantity, pinocchio's habit: [`forward`] (rigid TCP), [`deflection`] (every
//! [`Load`]: rigid, exact or linearized, with or without the arm's own link loads; the
//! Jacobian and the per-spring moments and angles are read from [`Data`] after it),
//! [`compliance`] (the 6x6 Cartesian compliance), [`joint_jacobian`], and the solvers built on
//! them ([`joint_correction`], [`equilibrium`]).

mod chain;
mod correction;
mod data;
mod deflection;
#[cfg(feature = "alloc")]
mod equilibrium;
mod lanes;
mod loads;
mod model;
mod rotation;
mod rows;
mod trig;
mod turns;

pub use correction::{
    JointCorrection, MAX_CORRECTION_ITERATIONS, POSE_TOLERANCE, commanded_pose, joint_correction,
    joint_delta, pose_from_matrix, rotation_from_matrix,
};
pub(crate) use data::check_joint_range;
pub use data::{Data, MAX_JOINT_POSITION};
pub use deflection::{compliance, deflection, forward, joint_jacobian, linear_deflection};
#[cfg(feature = "alloc")]
pub use equilibrium::{Equilibrium, EquilibriumOptions, equilibrium};
pub use loads::{ArmMotion, Deflection, Load, tcp_acceleration_bias};
pub use model::{
    Element, MAX_DOF, MAX_ELEMENTS, MAX_MASSES, MAX_SPRINGS, Model, ModelBuilder, valid_stiffness,
};
pub use rotation::MAX_SPRING_ANGLE;
pub(crate) use rotation::rotation_vector;
pub use rows::exact_deflection_x4;

/// A 6-vector `[x, y, z, rx, ry, rz]`: a wrench `[Fx, Fy, Fz, Mx, My, Mz]` \[N, N m\] or a small
/// pose change `[dx, dy, dz, rx, ry, rz]` \[m, rad\] (rotation vector), always in the base frame.
pub type Vector6 = nalgebra::Vector6<f64>;
