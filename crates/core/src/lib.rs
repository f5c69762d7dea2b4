//! # deflect-core
//!
//! Compliant-deflection models of robots and the real-time pieces that cancel that
//! deflection. Everything here is `#![no_std]`; the `alloc` and `std` features add the
//! conveniences that need a heap (loaders, fitting), and `urdf` loads serial robots from a
//! URDF plus a stiffness TOML file.
//!
//! Units are SI throughout: m, N, N m, rad, s, kg. Loaders of files in other units convert
//! explicitly and say so.
//!
//! Per-tick functions follow pinocchio's layout: an immutable model built once, a [`vjm::Data`]
//! that owns every buffer, and functions of `(&Model, &mut Data, inputs)` that allocate nothing,
//! never panic and return a typed [`error::TickError`] for wrong-sized or non-finite input.
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
#![warn(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

pub mod compensation;
pub mod compliance_map;
pub mod contour;
pub mod dalembert;
pub mod drivetrain;
pub mod error;
#[cfg(feature = "std")]
pub mod identification;
pub mod mechanism;
pub mod motion;
pub mod vjm;

#[cfg(feature = "urdf")]
pub mod drivetrain_io;
#[cfg(feature = "urdf")]
pub mod robot;

#[cfg(feature = "alloc")]
pub use compliance_map::ComplianceMap;
pub use compliance_map::{
    ComplianceMapError, ComplianceMapView, Interpolation, OutOfGrid, QueryError, QueryOptions,
    QueryStatus,
};
pub use error::{BuildError, TickError};
pub use vjm::{Data, Model, ModelBuilder};

#[cfg(feature = "urdf")]
pub use robot::{LoadError, SerialRobot};
