//! Compile-time check that deflect-core's real-time paths need neither `std` nor `alloc`.
//!
//! This crate is `#![no_std]`, has no `extern crate alloc`, and depends on deflect-core with
//! `default-features = false`. It builds every per-tick concept in its tick shape (`Model`,
//! `Data::new(&model)`, `fn(&Model, &mut Data, inputs)`) and calls what a controller runs:
//! VJM deflection and compliance, a compliance-map query, trajectory sampling, the D'Alembert
//! corrector, online compensation, drive-train correction and the contour tracer. Build it
//! alone (`cargo build -p deflect-nostd-check`): built together with the rest of the
//! workspace, cargo unifies deflect-core's features and the check proves nothing.
#![no_std]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![deny(missing_docs)]

use deflect_core::compensation::{self, CompensatorConfig, CycleOutput, SensorCalibration};
use deflect_core::compliance_map::{self, ComplianceMapView, OutOfGrid, QueryOptions};
use deflect_core::contour::{self, TracerConfig, TracerStep};
use deflect_core::dalembert::parallel::{self, Tick};
use deflect_core::drivetrain::{self, JointErrors};
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Limits, Trajectory};
use deflect_core::vjm::{self, Data, Model, ModelBuilder, Vector6};
use deflect_core::{BuildError, TickError};
use nalgebra::{Isometry3, Matrix2, Matrix6, Vector2, Vector3};

/// Why a check call failed (a `no_std` error type: no strings, no heap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CheckError {
    /// Model building failed.
    Build(BuildError),
    /// A per-tick call refused its input.
    Tick(TickError),
}

impl From<BuildError> for CheckError {
    fn from(e: BuildError) -> Self {
        Self::Build(e)
    }
}

impl From<TickError> for CheckError {
    fn from(e: TickError) -> Self {
        Self::Tick(e)
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
    let d = vjm::deflection(model, data, q, wrench, vjm::Load::Exact)?;
    let c = vjm::compliance(model, data, q)?;
    Ok((d, c))
}

/// The paper's 3 x 5 grid \[m\].
pub const GRID_X: [f64; 3] = [0.172132, 0.222132, 0.272132];
/// The paper's 3 x 5 grid \[m\].
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

/// A map query in the tick shape: displacement \[m\] at `position` under `force` \[N\].
pub fn map_lookup(
    view: &ComplianceMapView<'_>,
    data: &mut compliance_map::Data,
    position: [f64; 2],
    force: [f64; 2],
) -> Result<[f64; 2], CheckError> {
    compliance_map::step(view, data, position, &force)?;
    Ok([data.displacement[0], data.displacement[1]])
}

/// The D'Alembert corrector of the paper's robot over a borrowed map.
pub type Corrector<'a> = parallel::Model<ParallelRobot2, ComplianceMapView<'a>>;

/// The corrector with the paper's mass parameter.
pub fn corrector<'a>(view: ComplianceMapView<'a>) -> Result<Corrector<'a>, CheckError> {
    Ok(parallel::Model::new(
        ParallelRobot2::paper(),
        view,
        parallel::PAPER_MASS,
    )?)
}

/// One 2 kHz D'Alembert tick of the paper's robot at time `t` of `trajectory`.
pub fn dalembert_tick(
    model: &Corrector<'_>,
    data: &mut parallel::Data<(), (), 2>,
    trajectory: &Trajectory<2>,
    t: f64,
) -> Result<Tick<2, 2>, CheckError> {
    let s = trajectory.sample(t)?;
    Ok(parallel::step(model, data, &s.position, &s.acceleration)?)
}

/// The paper's 150 mm y-line, planned without a heap.
pub fn y_line(limits: &Limits) -> Result<Trajectory<2>, CheckError> {
    Ok(Trajectory::line(
        Vector2::new(0.222132, -0.075),
        Vector2::new(0.222132, 0.075),
        limits,
    )?)
}

/// The online compensation chain of `chain` at 2 kHz with the paper's settings.
pub fn compensator(chain: Model) -> Result<compensation::Model, CheckError> {
    let config = CompensatorConfig::paper(0.0005, SensorCalibration::default());
    Ok(compensation::Model::new(chain, config)?)
}

/// One compensation cycle.
pub fn compensation_tick(
    model: &compensation::Model,
    data: &mut compensation::Data,
    q: &[f64; 2],
    reading: &Vector6,
) -> Result<CycleOutput, CheckError> {
    let feed = Vector3::new(0.05, 0.0, 0.0);
    Ok(compensation::step(model, data, q, reading, None, &feed)?)
}

/// The drive train of `chain`: joint stiffnesses and backlashes, standard gravity.
pub fn drive_train(chain: Model) -> Result<drivetrain::Model, CheckError> {
    Ok(drivetrain::Model::new(
        chain,
        &[2.0e4, 1.0e4],
        &[1.0e-4, 1.0e-4],
    )?)
}

/// Eq. 10 of the contour-tracking paper at readings `q` under the tool wrench `wrench`.
pub fn drive_tick(
    model: &drivetrain::Model,
    data: &mut drivetrain::Data,
    q: &[f64; 2],
    wrench: &Vector6,
) -> Result<JointErrors, CheckError> {
    Ok(drivetrain::step(model, data, q, wrench)?)
}

/// A contour tracer with a 1 mm step, a 2..20 N window and a diagonal 1e5 N/m stiffness.
pub fn tracer() -> Result<contour::Model, CheckError> {
    let k = Matrix2::new(1.0e5, 0.0, 0.0, 1.0e5);
    Ok(contour::Model::new(
        TracerConfig::new(1.0e-3, 2.0, 20.0),
        &k,
    )?)
}

/// One tracer step.
pub fn tracer_tick(
    model: &contour::Model,
    data: &mut contour::Data,
    position: &Vector2<f64>,
    force: &Vector2<f64>,
) -> Result<TracerStep, CheckError> {
    Ok(contour::step(model, data, position, force)?)
}
