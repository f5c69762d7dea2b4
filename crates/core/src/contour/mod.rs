//! Force-feedback contour tracing of an unknown planar object by a position-controlled robot,
//! after "Shape recovery from robot contour tracking with force feedback", section 3
//! (Eq. 11-24, Figures 3-4).
//!
//! * The contact force model: a robot of xy stiffness `K` demanded to `x_d` but stopped at
//!   `x` pushes with `F = K (x_d - x)` (Eq. 11); a demanded step `D` against an edge at angle
//!   `theta_2` slides the tool by the projection of `D` on the edge (Eq. 16-17) and leaves the
//!   error `e` of Eq. 18-19, `F = K e` (Eq. 20).
//! * The edge direction from the steady-state force (Eq. 21): the tool moved by
//!   `D - K^-1 F` along the edge, so `theta_2 = atan2(D_y - [K^-1 F]_y, D_x - [K^-1 F]_x)`.
//! * The tracer: the algorithm of Figures 3-4 as a state machine that consumes one
//!   steady-state force reading per [`step`] and returns the next position command; its
//!   [`Model`] is the validated [`TracerConfig`] and initial stiffness, its [`Data`] the
//!   tracer's state.
//!
//! Forces here are the force the **tool exerts on the object** (it points into the object),
//! in the xy plane of the base frame \[N\]; positions \[m\], angles \[rad\]. Everything is
//! allocation-free and panic-free; bad input is a [`crate::TickError`] (a bad configuration
//! a [`crate::BuildError`]), a failed trace a [`TracerState::Failed`] status.

mod config;
mod geometry;
pub mod shape;
mod tracer;

pub use config::{
    TraceDirection, TraceFailure, TracerConfig, TracerState, TracerStats, TracerStep,
};
pub use geometry::{
    MIN_RECIPROCAL_CONDITION, compliance_of, contact_force, edge_contact_force, edge_direction,
    edge_displacement, edge_motion,
};
pub use tracer::{Data, Model, step};
