//! The offline pass over a five-axis program: the tool axis of the program
//! ([`super::Move::axis`], sampled by [`super::path`]) in the target pose, the force of each
//! cutter along its edge ([`super::profile`]: Lee and Altintas' model, the flat, ball and
//! bull-nose ends) on the engagement read from a tri-dexel stock ([`super::dexel`]), the
//! exact virtual-joint deflection (Hähn and Weigold 2020, sec. 2.2, Eq. 2-9) of the position
//! *and the tilt*, and the compensated joints at which the loaded arm holds the programmed
//! pose. The predicted part in 3-D is the stock cut by each predicted tool
//! ([`Report::uncompensated`], [`Report::compensated`]), compared along its surface's normal
//! with the nominal one by [`super::dexel::surface`].
//!
//! Per sample (workpiece frame `W`, placed at [`Setup::placement`](super::job::Setup)):
//!
//! 1. the nominal stock holds every move before the sample's (cut whole by
//!    [`Dexels::cut_move`]); the engagement of the tool at the programmed tip and axis is read
//!    from it ([`Dexels::engagement`]). The part of the current move the tool has already
//!    run is not cut yet, which changes nothing: it lies behind the tool, where the chip
//!    `h = f . n` of the model is negative and cuts nothing;
//! 2. the wrench about the tip is the per-revolution average along the edge
//!    ([`super::profile::average`]) at the feed per tooth as a tool-frame vector (a tool tilted
//!    to the feed moves along its axis too, [`super::profile::tool_feed`]);
//! 3. the target pose is the setup's tool orientation turned by the shortest rotation from
//!    `+z` to the program's axis ([`orientation`]), then about that axis by the job's spin
//!    schedule ([`Job::with_spin`]; [`crate::machining::spin::LoadPath::new_five_axis`] finds
//!    one, from [`nominal_pass`]); the rigid joints `q` (pose IK) and the deflected pose there
//!    under the wrench are the uncompensated tool; the compensated joints `q_c` solve the
//!    pose IK of the loaded chain, and the deflected pose at `q_c`, evaluated again by the
//!    exact VJM (not taken from the IK), is the compensated tool;
//! 4. each predicted tool cuts its own stock along chords through its samples (and the
//!    program's corners between them) that stay within [`CHORD_TOLERANCE`] of them, and so
//!    does the programmed tool for the nominal part ([`Report::nominal`]).
//!
//! # What this pass does not model (the 2.5-D [`super::job`] does)
//! The force is the nominal tool's on the nominal stock: the predicted tools feel the same
//! force, where the z-map job solves the force-deflection coupling on each tool's own stock.
//! The spindle turns clockwise (`M4` is refused); a rapid through material is cut and reported
//! ([`Report::rapid_volume`]), not refused; an axis turn without tip motion is taken
//! between two samples.

use alloc::vec::Vec;

use nalgebra::{UnitQuaternion, Vector3};

use super::Program;
use super::dexel::Dexels;
use super::job::Job;
use super::kinematics::ToolPose;
use super::path::PathSample;
use super::profile::ToolShape;
use crate::error::{BuildError, TickError, param};
use crate::vjm::{MAX_DOF, Vector6};

mod cutter;
mod follow;
mod pass;

pub use cutter::{CutterModel, edge_wrench, frame};
pub use pass::{nominal_pass, run};

/// How far a predicted tool's cut may leave its samples \[m\]: a quarter of
/// [`super::job::PREDICTION_TOLERANCE`] (the stock's surface is exact along its rays, so the
/// chords, not the cells, bound what the predicted part misses of the tool's path).
pub const CHORD_TOLERANCE: f64 = 2.5e-7;

/// What the five-axis pass needs beyond the [`Job`]: the stock's depth, the cutter (when the
/// job has no tool table) and how finely the engagement is read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The stock's depth below [`super::job::Stock::top`] \[m\], `(0, 1]`: the dexel block
    /// spans the job's stock in x and y and this in z.
    pub depth: f64,
    /// The end of the setup's tool ([`super::job::Setup::tool`]) when the job has no tool
    /// table (a table's tools carry their own).
    pub shape: ToolShape,
    /// The length of every tool that removes material \[m\] (flutes and the shank that would
    /// rub; a tool table's lengths are the tools' offsets, not this).
    pub length: f64,
    /// Axial slices of the edge the engagement is read in, `1..=256`.
    pub slices: usize,
    /// Immersion angles per slice, `1..=3600`.
    pub angles: usize,
}

impl Default for Options {
    /// 50 mm of stock, a flat end 30 mm long, 32 slices of 180 angles (2 degrees).
    fn default() -> Self {
        Self {
            depth: 0.05,
            shape: ToolShape::Flat,
            length: 0.03,
            slices: 32,
            angles: 180,
        }
    }
}

impl Options {
    /// Checks every option ([`BuildError::InvalidParameter`] naming it).
    pub fn validate(&self) -> Result<(), BuildError> {
        param(
            "five-axis stock depth (m)",
            self.depth,
            self.depth > 0.0 && self.depth <= 1.0,
            "in (0, 1] m",
        )?;
        param(
            "engagement slices",
            self.slices as f64,
            (1..=256).contains(&self.slices),
            "1..=256",
        )?;
        param(
            "engagement angles",
            self.angles as f64,
            (1..=3600).contains(&self.angles),
            "1..=3600",
        )?;
        Ok(())
    }
}

/// One sample of the five-axis pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The programmed tool (tip, axis, feed direction, ...), workpiece frame.
    pub path: PathSample,
    /// Feed per tooth \[m\] (0 off the cut).
    pub feed_per_tooth: f64,
    /// Engaged bands along the edge (0: the tool cuts air).
    pub bands: usize,
    /// Force on the tool \[N\], workpiece frame.
    pub force: Vector3<f64>,
    /// The wrench about the tip \[N, N m\], workpiece frame.
    pub wrench: Vector6,
    /// Rigid pose-IK joints \[rad or m\] (entries past the dof 0).
    pub q: [f64; MAX_DOF],
    /// Compensated joints \[rad or m\].
    pub q_commanded: [f64; MAX_DOF],
    /// The tool the uncompensated arm holds under the wrench, workpiece frame.
    pub uncompensated: ToolPose,
    /// The tool the compensated arm holds under the wrench, workpiece frame.
    pub compensated: ToolPose,
    /// The spin about the tool axis \[rad\] (the job's schedule; 0 without one).
    pub spin: f64,
}

impl Sample {
    /// How far a predicted tool is from the program: its tip \[m\] and the angle of its axis
    /// \[rad\].
    pub fn error(&self, compensated: bool) -> (f64, f64) {
        let t = if compensated {
            &self.compensated
        } else {
            &self.uncompensated
        };
        (
            (t.tip - self.path.position).norm(),
            super::program::angle_between(&t.axis, &self.path.axis),
        )
    }
}

/// The largest and root-mean-square errors of a predicted tool over the cutting samples.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ToolErrors {
    /// Largest tip error \[m\].
    pub max_position: f64,
    /// Root mean square of the tip error \[m\].
    pub rms_position: f64,
    /// Largest axis error \[rad\].
    pub max_axis: f64,
    /// The program line of the largest tip error (0 without cutting samples).
    pub line: usize,
}

/// What the five-axis pass gives.
#[derive(Debug, Clone)]
pub struct Report {
    /// Every sample, in time order.
    pub samples: Vec<Sample>,
    /// The stock cut by the program as sampled: the tool on the program at every sample and
    /// between them where the program bends, cut along the chords the predicted tools' cuts
    /// take (so the parts' differences are the tools', not the cuts' discretisation).
    pub nominal: Dexels,
    /// The stock cut by the uncompensated tool.
    pub uncompensated: Dexels,
    /// The stock cut by the compensated tool.
    pub compensated: Dexels,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
    /// The arm's joints.
    pub dof: usize,
    /// Rays the three stocks' cuts changed.
    pub ray_updates: usize,
    /// Material the program's rapids removed from the nominal stock \[m^3\] (0 for a program
    /// that never rapids through the stock).
    pub rapid_volume: f64,
}

impl Report {
    /// The errors of the uncompensated or compensated tool over the samples that cut.
    pub fn errors(&self, compensated: bool) -> ToolErrors {
        let mut e = ToolErrors::default();
        let (mut sum, mut n) = (0.0, 0usize);
        for s in self.samples.iter().filter(|s| s.bands > 0) {
            let (p, a) = s.error(compensated);
            if p > e.max_position {
                e.max_position = p;
                e.line = s.path.line;
            }
            e.max_axis = e.max_axis.max(a);
            sum += p * p;
            n += 1;
        }
        if n > 0 {
            e.rms_position = nalgebra::ComplexField::sqrt(sum / n as f64);
        }
        e
    }
}

/// One cutter of the program: its number, model, and whether the job knows it.
#[derive(Debug, Clone, Copy)]
struct Cutter {
    number: u32,
    model: CutterModel,
    known: bool,
}

fn cutters(job: &Job, program: &Program, options: &Options) -> Result<Vec<Cutter>, BuildError> {
    let setup = job.setup();
    let mut list = Vec::new();
    for number in program.tools() {
        let (tool, shape, known) = match job.tools() {
            None => (setup.tool, options.shape, true),
            Some(table) => match table.get(number) {
                Some(spec) => (spec.tool, spec.shape, true),
                None => (setup.tool, options.shape, false),
            },
        };
        let model = CutterModel::new(&tool, shape, options.length)?;
        param(
            "stock cell (m), at most half the radius of every tool the program uses",
            setup.stock.cell,
            setup.stock.cell <= 0.5 * model.profile.radius(),
            "<= the radius / 2 of the program's smallest tool",
        )?;
        list.push(Cutter {
            number,
            model,
            known,
        });
    }
    Ok(list)
}

fn find(cutters: &[Cutter], number: u32) -> Option<&Cutter> {
    cutters.iter().find(|c| c.number == number)
}

/// The target rotation for tool axis `axis` (workpiece frame): the setup's orientation turned
/// by the shortest rotation from `+z` to the axis (the setup's own for `+z`, bit for bit).
/// [`TickError::InvalidArgument`] for an axis pointing down the workpiece z.
pub fn orientation(
    tool_orientation: &UnitQuaternion<f64>,
    axis: &Vector3<f64>,
) -> Result<UnitQuaternion<f64>, TickError> {
    if *axis == Vector3::z() {
        return Ok(*tool_orientation);
    }
    let turn = UnitQuaternion::rotation_between(&Vector3::z(), axis).ok_or(
        TickError::InvalidArgument {
            what: "tool axis (pointing down the workpiece z: no shortest turn from +z)",
            value: axis.z,
        },
    )?;
    Ok(turn * tool_orientation)
}
