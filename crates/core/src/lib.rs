//! # deflect-core
//!
//! Compliant-deflection models of robots and the real-time pieces that cancel that
//! deflection: the virtual-joint model of a serial robot (Hähn and Weigold), compliance maps
//! from static tests and the D'Alembert trajectory corrector (Paksoy, Dede and Kiper 2025),
//! online force-based compensation, drive-train errors and force-feedback contour tracing.
//! Everything here is `#![no_std]`; the `alloc` and `std` features add what needs a heap
//! (fitting, identification, loaders in [`io`]), and `urdf` loads serial robots from a URDF
//! plus a stiffness TOML file.
//!
//! Units are SI throughout: m, N, N m, rad, s, kg ([`units`]). Loaders of files in other
//! units convert explicitly and say so.
//!
//! ## One tick shape
//!
//! Every per-tick concept follows pinocchio's layout: an immutable `Model` built and
//! validated once, a `Data::new(&model)` that owns every buffer the tick needs and can
//! `check(&model)`, and per-tick functions `fn(&Model, &mut Data, inputs) -> Result<_,
//! TickError>` that allocate nothing and never panic. Errors come in three tiers
//! ([`error`]): [`BuildError`] / [`LoadError`] when a model is assembled or loaded,
//! [`TickError`] per tick, numerical failure inside a solver as an `Option`.
//!
//! | concept with per-tick state | model | tick |
//! |---|---|---|
//! | D'Alembert correction, parallel robot + compliance map | [`dalembert::parallel::Model`] | [`dalembert::parallel::step`] |
//! | D'Alembert correction, serial arm + VJM | [`dalembert::serial::Model`] | [`dalembert::serial::step`] |
//! | online compensation | [`compensation::Model`] | [`compensation::step`] |
//! | drive-train errors | [`drivetrain::Model`] | [`drivetrain::step`] |
//! | contour tracing | [`contour::Model`] | [`contour::step`] |
//! | compliance-map query | [`compliance_map::Model`] | [`compliance_map::step`] |
//! | trajectory sampling | [`motion::Model`] | [`motion::step`] |
//!
//! Quantities without per-tick state are one function each over the same `(&Model, &mut
//! Data, inputs)`: the virtual-joint model's [`vjm::forward`], [`vjm::deflection`] (one pass
//! for every [`vjm::Load`]), [`vjm::compliance`], [`vjm::joint_correction`]; a mechanism's
//! `inverse` and `forward` ([`mechanism::Mechanism`]).
//!
//! ```
//! use deflect_core::vjm::{self, Data, Vector6};
//! use deflect_core::ModelBuilder;
//! use nalgebra::{Isometry3, Vector3};
//! // A 1 m arm about z with a spring at its joint: 1e4 N m/rad about z.
//! let model = ModelBuilder::new()
//!     .revolute(Vector3::z())?
//!     .spring([f64::INFINITY, f64::INFINITY, 1.0e4])?
//!     .fixed(Isometry3::translation(1.0, 0.0, 0.0))?
//!     .build()?;
//! let mut data = Data::new(&model);
//! // 100 N along +y at the tip: moment 100 N m, angle 0.01 rad, tip moves ~10 mm along y.
//! let w = Vector6::new(0.0, 100.0, 0.0, 0.0, 0.0, 0.0);
//! let d = vjm::deflection(&model, &mut data, &[0.0], &w, vjm::Load::Exact)?;
//! assert!((d.y - 0.01f64.sin()).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![no_std]
// The real-time core must never panic: these are hard errors here (tests may unwrap).
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

pub mod compensation;
pub mod compliance_map;
pub mod contour;
pub mod controller;
pub mod dalembert;
pub mod drivetrain;
pub mod error;
pub mod geometry;
mod golden;
#[cfg(feature = "std")]
pub mod identification;
#[cfg(feature = "std")]
pub mod io;
pub mod machining;
pub mod mechanism;
pub mod motion;
pub mod posture;
#[cfg(feature = "std")]
pub mod robot;
pub mod units;
pub mod vjm;

#[cfg(feature = "alloc")]
pub use compliance_map::ComplianceMap;
pub use compliance_map::{ComplianceMapView, Interpolation, OutOfGrid, QueryOptions};
#[cfg(feature = "std")]
pub use error::LoadError;
pub use error::{BuildError, JobError, Placement, TickError};
#[cfg(feature = "std")]
pub use robot::SerialRobot;
pub use vjm::{Data, Model, ModelBuilder};
