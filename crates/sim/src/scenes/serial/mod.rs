//! The serial testbed: a flexible arm from any URDF and stiffness file in rapier
//! ([`crate::urdf_arm`]) carries a payload through a line and a circle in pose at high
//! acceleration, commanded by the rigid inverse kinematics (uncorrected) or by deflect-core's
//! 6-D D'Alembert corrector for serial arms (`dalembert::serial`: the payload's inertial
//! wrench through the virtual-joint deflection, loaded-pose IK per tick).
//!
//! Per run the servo gets the joint command of each 2 kHz tick with its rate and acceleration
//! (backward differences, as in the five-bar scene); the TCP pose after each physics step is
//! compared with the desired pose of that tick: the distance from the planned path, the
//! tracking error and the orientation error, over the motion. The static compliance of the
//! rapier arm at the start pose is checked against deflect-core's `J K^-1 J^T` first.

pub mod atlas;
pub mod motion;
pub mod output;
pub mod run;

pub use motion::{MotionParams, PathKind};
pub use run::{
    SerialMetrics, SerialOptions, SerialResult, SerialRun, SerialSample, check_motions, evaluate,
    plan, run, serial, static_check,
};
