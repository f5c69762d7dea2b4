//! Compile-time check that deflect-core's real-time paths need neither `std` nor `alloc`.
//!
//! This crate is `#![no_std]`, has no `extern crate alloc`, and depends on deflect-core with
//! `default-features = false`. It calls the per-tick functions a controller runs: VJM
//! deflection and compliance, a compliance-map view lookup, trajectory sampling and the
//! D'Alembert corrector step. Build it alone (`cargo build -p deflect-nostd-check`): built
//! together with the rest of the workspace, cargo unifies deflect-core's features and the
//! check proves nothing.
#![no_std]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![warn(missing_docs)]

use deflect_core::compliance_map::{ComplianceMapView, OutOfGrid, QueryOptions};
use deflect_core::dalembert::{CorrectedTick, DalembertCorrector};
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Limits, Trajectory};
use deflect_core::vjm::{self, Data, Model, ModelBuilder, Vector6};
use deflect_core::{BuildError, ComplianceMapError};
use nalgebra::{Isometry3, Matrix6, Vector2, Vector3};

/// Why a check call failed (a `no_std` error type: no strings, no heap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CheckError {
    /// Model building failed.
    Build(BuildError),
    /// A per-tick call refused its input.
    Tick,
    /// The map tables are invalid.
    Map,
}

impl From<BuildError> for CheckError {
    fn from(e: BuildError) -> Self {
        Self::Build(e)
    }
}

impl From<ComplianceMapError> for CheckError {
    fn from(_: ComplianceMapError) -> Self {
        Self::Map
    }
}

/// A two-joint planar arm with a soft spring at each joint, built without a heap.
pub fn two_link_arm() -> Result<Model, CheckError> {
    Ok(ModelBuilder::new()
        .revolute(Vector3::z())?
        .spring([1.0e6, 1.0e6, 2.0e5])?
        .fixed(Isometry3::translation(0.5, 0.0, 0.0))?
        .revolute(Vector3::z())?
        .spring([f64::INFINITY, f64::INFINITY, 1.0e5])?
        .fixed(Isometry3::translation(0.4, 0.0, 0.0))?
        .build()?)
}

/// `vjm::deflection` and `vjm::compliance` at `q` under `wrench`.
pub fn vjm_tick(
    model: &Model,
    data: &mut Data,
    q: &[f64; 2],
    wrench: &Vector6,
) -> Result<(Vector6, Matrix6<f64>), CheckError> {
    let d = vjm::deflection(model, data, q, wrench).map_err(|_| CheckError::Tick)?;
    let c = vjm::compliance(model, data, q).map_err(|_| CheckError::Tick)?;
    Ok((d, c))
}

/// The paper's 3 x 5 grid [m].
pub const GRID_X: [f64; 3] = [0.172132, 0.222132, 0.272132];
/// The paper's 3 x 5 grid [m].
pub const GRID_Y: [f64; 5] = [-0.075, -0.0375, 0.0, 0.0375, 0.075];

/// A borrowed, allocation-free compliance map over static tables (2 force, 2 displacement
/// axes), clamping outside the grid.
pub fn map_view<'a>(
    slopes: &'a [f64; 60],
    offsets: &'a [f64; 60],
) -> Result<ComplianceMapView<'a>, CheckError> {
    Ok(
        ComplianceMapView::new(&GRID_X, &GRID_Y, 2, 2, slopes, offsets)?.with_options(
            QueryOptions {
                out_of_grid: OutOfGrid::Clamp,
                ..QueryOptions::default()
            },
        ),
    )
}

/// A map-view lookup: displacement [m] at `position` under `force` [N].
pub fn map_lookup(
    view: &ComplianceMapView<'_>,
    position: [f64; 2],
    force: [f64; 2],
) -> Result<[f64; 2], CheckError> {
    let mut out = [0.0; 2];
    view.displacement(position, &force, &mut out)
        .map_err(|_| CheckError::Tick)?;
    Ok(out)
}

/// One 2 kHz D'Alembert tick of the paper's robot at time `t` of `trajectory`.
pub fn dalembert_tick(
    view: &ComplianceMapView<'_>,
    trajectory: &Trajectory<2>,
    t: f64,
    seed: &Vector2<f64>,
) -> Result<CorrectedTick<2, 2>, CheckError> {
    let corrector =
        DalembertCorrector::new(DalembertCorrector::PAPER_MASS).map_err(|_| CheckError::Tick)?;
    let s = trajectory.sample(t).map_err(|_| CheckError::Tick)?;
    corrector
        .step(
            &ParallelRobot2::paper(),
            view,
            &s.position,
            &s.acceleration,
            seed,
        )
        .map_err(|_| CheckError::Tick)
}

/// The paper's 150 mm y-line, planned without a heap.
pub fn y_line(limits: &Limits) -> Result<Trajectory<2>, CheckError> {
    Trajectory::line(
        Vector2::new(0.222132, -0.075),
        Vector2::new(0.222132, 0.075),
        limits,
    )
    .map_err(|_| CheckError::Tick)
}
