//! `contour` scenario: force-feedback contour tracing of unknown planar objects and shape
//! recovery with drive-train compensation, after "Shape recovery from robot contour tracking
//! with force feedback", sections 2-3 (Eq. 10, Eq. 21), Figures 6-8.
//!
//! * [`arm`]: a planar 2R arm in the horizontal plane (joint axes vertical, so gravity loads
//!   no joint), two links as rapier3d-f64 multibody bodies on revolute-z joints. Each joint is
//!   driven by an ideal position servo (the motor angle follows the command on a cosine ramp)
//!   through a drive train that rapier's joint springs cannot express: a spring with a dead
//!   zone of `+-backlash` (total play `2 backlash`) plus a relative viscous damper, computed
//!   per physics step and applied as a torque pair on the link and its parent.
//!   `tau = K dz(q_motor - q_link) + c (w_motor - w_link)`.
//! * Contact: a penalty force computed from the tool point's penetration into the objects
//!   ([`objects`]: spring `k_contact`, damper `c_contact` on the inward velocity, never
//!   pulling), no friction; only the tool point touches (the links pass above the objects).
//! * [`run`]: the force sensor at the tool reads the mean contact force over the last
//!   `average` seconds of each settle, plus a constant bias and seeded Gaussian noise on every
//!   physics-step sample. deflect-core's tracer ([`deflect_core::contour::step`]) consumes one
//!   settled reading per step; its command goes through the closed-form IK to the motors. On
//!   each contact sample the motor readings are recorded; the shape is recovered raw (FK of
//!   the motor readings) and compensated (Eq. 10, [`deflect_core::drivetrain::step`]
//!   with the arm's stiffness, backlash and masses and the sensed force).
//! * [`output`]: summary table, CSV, JSON, MCAP log and one plot per object.

pub mod arm;
pub mod objects;
pub mod output;
pub mod run;

pub use arm::{ArmParams, ArmSim};
pub use objects::{ObjectSpec, Outline, default_objects};
pub use run::{ContourRun, Sample, ShapeErr, TraceOptions, trace, trace_all};

use crate::SimError;

/// Physics time step of the contour scene \[s\].
pub const DT: f64 = 0.5e-3;

/// A contour-scene error with the context "contour".
fn err<E: core::fmt::Display>(e: E) -> SimError {
    SimError::new(format!("contour: {e}"))
}
