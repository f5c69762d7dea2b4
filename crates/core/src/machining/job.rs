//! The offline pass of the hybrid compensation of Hähn and Weigold (2020, sec. 2.3-2.4) over a
//! user's program: the program driven at its feeds ([`super::path`]), the stock cut along it
//! ([`super::stock`]) with the chip read at every sample ([`super::engagement`]), the
//! mechanistic per-revolution force of that chip ([`super::chip`]) turned into the TCP wrench,
//! the exact virtual-joint deflection (Eq. 2-9 of the paper) at the rigid pose-IK joints, and
//! the compensated joints at which the *loaded* arm lands on the programmed pose.
//!
//! Per sample (workpiece frame `W`, placed at [`Setup::placement`] in the base frame):
//!
//! 1. the programmed tool tip `p` and the chip of the nominal tool on the nominal stock, the
//!    force `F` on the tool and the wrench about the tip (each angle's force halfway up its
//!    depth, the cutting torque about the axis); then the nominal stock is cut to `p` (a
//!    straight run of samples held back and cut as one move, [`super::stock::Follower`]);
//! 2. the target pose `placement * (p, tool_orientation)`, the rigid joints `q` by pose IK
//!    warm-started from the previous samples, the deflection of the tip under the wrench at
//!    `q` (exact VJM), and the compensated joints `q_c` at which the loaded tip reaches the
//!    target (pose IK of the loaded chain); the Cartesian command is the rigid pose at `q_c`,
//!    the axis-specific one `q_c - q`;
//! 3. the part, predicted three ways on three z-maps: nominal (the tool on the program),
//!    uncompensated (at `q`) and compensated (at `q_c`). Each prediction's tool feels the force
//!    of its own chip where it is: its tip `t` solves `t = tip(q, F(t))` on its own stock, by
//!    fixed-point iteration from the previous sample's tip plus the programmed step (and, for
//!    the uncompensated tool, its last drift), to [`COUPLING_TOLERANCE`] within
//!    [`MAX_COUPLING_ITERATIONS`] (the last step is reported per sample,
//!    [`JobSample::coupling_residual`]); then its stock is cut to `t`, in moves that end at
//!    the samples the nominal stock's moves end at (so the three stocks are cut alike).
//!
//! # How close the compensated prediction stays to the program
//! The compensated joints put the loaded tip on `p` to the IK's position tolerance `e_ik`
//! under the nominal force. The compensated tool feels `F(t)` instead, on a stock its own
//! past cut, so `|t - p| <= e_ik + |C| |F(t) - F(p)|` with `|C|` the arm's compliance. The
//! force is continuous in the tool's position ([`super::chip`]: `|F(t) - F(p)| <= W (|d_z| +
//! sqrt(2) D / cell |d_xy|)`) and the stocks agree to the earlier deviations, so where `|C| W`
//! stays below 1 the deviation stays within `e_ik / (1 - |C| W)` plus the coupling residual:
//! 1e-8 m on the KR 300 (`|C| W` about 0.1-0.5 in aluminium). [`PREDICTION_TOLERANCE`] (1 um)
//! is what the report holds it to; lines past it are named with the reason
//! ([`super::report::Deviation`]). A sample the arm cannot reach or the IK cannot solve is an
//! error naming its line.
//!
//! The tool axis is the workpiece's z (a 2.5-D program); the deflected tool's tilt
//! (milliradians) is not carried into the z-maps.
//!
//! A program of several tools cuts and feels the force of the tool in the spindle at each
//! move ([`crate::machining::Move::tool`]), looked up in the job's tool table
//! ([`Job::with_tools`]; without one, [`Setup::tool`] serves every `T`). A counter-clockwise
//! spindle (`M4`) cuts as the mirror image of a clockwise one about the feed direction. A
//! program that never starts its spindle (posts for hand-started spindles) cuts at
//! [`Setup::hand_spindle`].
//!
//! # Long programs
//! [`run`] keeps every sample (up to [`path::MAX_PATH_SAMPLES`](super::path::MAX_PATH_SAMPLES)); [`run_streaming`] hands
//! them to a sink chunk by chunk ([`RunOptions::chunk`]) and keeps only the z-maps, the plan
//! and the per-line figures ([`Summary`]): its memory does not grow with the program's
//! duration. With the `std` feature and [`RunOptions::threads`] above 1, the two predictions
//! of a chunk run on two threads once the nominal cut of the chunk is done, and the nominal
//! cut of the next chunk on a third beside them.

use alloc::vec::Vec;

use nalgebra::{Isometry3, Vector3};

use super::Program;
use super::chip::ChipModel;
use super::cutting::{self, Tool};
use super::engagement::{self, Chip};
use super::path::PathSample;
pub use super::report::{
    Deviation, ErrorStats, JobSample, LineForce, LineSummary, RapidContact, Report, Summary,
    SurfaceError,
};
use super::stock::Cutter;
use super::tools::ToolTable;
use crate::error::{BuildError, JobError, TickError};
use crate::vjm::{Model, Vector6};

mod inertia;
mod nominal;
mod offline;
mod predict;
mod setup;
mod streaming;
mod warm;

pub(crate) use warm::Warm;

pub use inertia::Inertia;
pub use nominal::{NominalSample, nominal_pass};
pub use offline::{run, run_streaming};
pub use setup::{Setup, Stock};
pub use streaming::{RunError, RunOptions, Sink};

pub use crate::mechanism::JOINT_LIMIT_TOLERANCE;

/// How deep a rapid move (`G0`) may run into the predicted stock before the job refuses it
/// as a crash \[m\], by default ([`Setup::rapid_skim`]): 0.1 mm. The stops between runs are
/// sampled at the controller rate, so the predicted floor where a cut stopped may stand a few
/// micrometres above the programmed one (tens at 125 Hz), and CAM programs rapid down to the
/// last cut's depth.
pub const RAPID_SKIM: f64 = 1.0e-4;

/// The arm, its joint limits and the job's setup: immutable once built.
#[derive(Debug, Clone)]
pub struct Job {
    model: Model,
    limits: Vec<(f64, f64)>,
    setup: Setup,
    tools: Option<ToolTable>,
    controller: Option<crate::controller::Convention>,
    spin: Option<super::spin::SpinSchedule>,
    inertia: Option<Inertia>,
}

impl Job {
    /// Validates the setup and the limits (one `(lower, upper)` per joint).
    pub fn new(model: Model, limits: &[(f64, f64)], setup: Setup) -> Result<Self, BuildError> {
        setup.validate()?;
        if limits.len() != model.dof() {
            return Err(BuildError::WrongLength {
                what: "joint limits",
                expected: model.dof(),
                got: limits.len(),
            });
        }
        for (index, &(lo, hi)) in limits.iter().enumerate() {
            if lo.is_nan() || hi.is_nan() || lo > hi {
                return Err(BuildError::InvalidEntry {
                    what: "joint limits (lower <= upper)",
                    index,
                    value: hi - lo,
                    expected: ">= 0 (upper minus lower)",
                });
            }
        }
        Ok(Self {
            model,
            limits: limits.to_vec(),
            setup,
            tools: None,
            controller: None,
            spin: None,
            inertia: None,
        })
    }

    /// The job with inertial loads ([`Inertia`], the `inertia` module's docs): the tool and
    /// spindle's D'Alembert wrench in the path's planned motion, and the link masses' loads,
    /// join the process wrench of every sample before the deflection, in the compensated
    /// joints and in both predictions; the report splits the deflection into its process and
    /// inertial parts ([`JobSample::deflection_inertial`]). An inertia that counts nothing
    /// ([`Inertia::is_zero`]) leaves the job as it was.
    pub fn with_inertia(mut self, inertia: Inertia) -> Result<Self, BuildError> {
        inertia.validate()?;
        self.inertia = (!inertia.is_zero()).then_some(inertia);
        Ok(self)
    }

    /// The inertial loads the job counts, if any.
    pub fn inertia(&self) -> Option<&Inertia> {
        self.inertia.as_ref()
    }

    /// The job with the tool turned about its own axis along the program by `schedule`
    /// ([`super::spin`]): each sample's target orientation is the setup's turned by the
    /// schedule's spin there.
    #[must_use]
    pub fn with_spin(mut self, schedule: super::spin::SpinSchedule) -> Self {
        self.spin = Some(schedule);
        self
    }

    /// The spin schedule, if the job has one (else the setup's orientation everywhere).
    pub fn spin(&self) -> Option<&super::spin::SpinSchedule> {
        self.spin.as_ref()
    }

    /// The job as it runs from `seed`: an arm of fewer than six joints cannot hold the full
    /// pose its setup asks for ([`crate::mechanism::Task::POSE`]), so it controls the largest
    /// task it has at the seed ([`crate::mechanism::largest_task`]: a SCARA its position and
    /// the spin about the tool axis, a 5-axis arm its position and the tool axis). The job
    /// itself otherwise.
    pub fn at_seed(&self, seed: &[f64]) -> Result<alloc::borrow::Cow<'_, Self>, JobError> {
        use alloc::borrow::Cow;
        let dof = self.model.dof();
        if dof >= 6 || self.setup.ik.task != crate::mechanism::Task::POSE || seed.len() != dof {
            return Ok(Cow::Borrowed(self));
        }
        let mut data = crate::vjm::Data::new(&self.model);
        let task =
            crate::mechanism::largest_task(&self.model, &mut data, seed).map_err(|error| {
                JobError::AtLine {
                    line: 0,
                    time: 0.0,
                    error,
                }
            })?;
        let mut job = self.clone();
        job.setup.ik.task = task;
        Ok(Cow::Owned(job))
    }

    /// The joint limits `(lower, upper)` \[rad or m\], one per joint.
    pub fn limits(&self) -> &[(f64, f64)] {
        &self.limits
    }

    /// The job with a tool table: each move cuts with the tool its program line put in the
    /// spindle (a program's `T` missing from the table is an error where that tool cuts).
    #[must_use]
    pub fn with_tools(mut self, tools: ToolTable) -> Self {
        self.tools = Some(tools);
        self
    }

    /// The job with its arm's controller convention (the robot programs of
    /// [`crate::io::robot_program`] read it; the pass does not).
    #[must_use]
    pub fn with_controller(mut self, controller: crate::controller::Convention) -> Self {
        self.controller = Some(controller);
        self
    }

    /// The arm's controller convention, if the job has one.
    pub fn controller(&self) -> Option<&crate::controller::Convention> {
        self.controller.as_ref()
    }

    /// The tool table, if the job has one.
    pub fn tools(&self) -> Option<&ToolTable> {
        self.tools.as_ref()
    }

    /// The cutter of tool number `t`: from the table, or [`Setup::tool`] without a table;
    /// `None` when the table lacks it.
    pub fn tool(&self, t: u32) -> Option<(Tool, Cutter)> {
        let flat = |tool: Tool| {
            (
                tool,
                Cutter::Flat {
                    radius: 0.5 * tool.diameter,
                },
            )
        };
        match &self.tools {
            None => Some(flat(self.setup.tool)),
            Some(table) => table.get(t).map(|spec| (spec.tool, spec.cutter())),
        }
    }

    /// The arm.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The setup.
    pub fn setup(&self) -> &Setup {
        &self.setup
    }
}

/// How close the fixed point of the force-deflection coupling gets \[m\]: 1e-8 m, the pose
/// IK's default position tolerance (the predicted tip is known no better than the joints
/// that put it there).
pub const COUPLING_TOLERANCE: f64 = 1.0e-8;
/// Most evaluations of the coupling per prediction and sample (fixed-point steps while they
/// contract by half or better, then Newton steps of four evaluations each); the residual is
/// reported when they run out.
pub const MAX_COUPLING_ITERATIONS: usize = 40;
/// How far the compensated prediction may leave the program \[m\] before the report names
/// the line and why ([`Deviation`]): 1 um.
pub const PREDICTION_TOLERANCE: f64 = 1.0e-6;
/// Samples per chunk of a streamed run by default: 4096 (16 s of program at 250 Hz, about
/// 2.5 MB of samples).
pub const DEFAULT_CHUNK: usize = 4096;
/// Most samples per chunk: 2^20.
pub const MAX_CHUNK: usize = 1 << 20;

/// The force on the tool \[N\] and the wrench about the tip \[N, N m\] (both workpiece frame)
/// of `chip` for the tool of `model`, moving along `feed` (workpiece frame, any length) at
/// `feed_per_tooth` \[m\]: zero for plunges and without a horizontal feed. A
/// `counter_clockwise` spindle (`M4`, its chip read mirrored by [`engagement::read`]) gives
/// the mirror image about the feed direction: the lateral force and the torques turn sign.
/// [`TickError::NonFiniteOutput`] for depths that overflow.
pub fn chip_wrench(
    model: &ChipModel,
    chip: &Chip,
    feed: &Vector3<f64>,
    feed_per_tooth: f64,
    counter_clockwise: bool,
) -> Result<(Vector3<f64>, Vector6), TickError> {
    let Some(frame) = cutting::tool_frame(&Vector3::z(), feed) else {
        return Ok((Vector3::zeros(), Vector6::zeros()));
    };
    let (mut f_tool, mut m_tool) = model.wrench(chip, feed_per_tooth);
    if counter_clockwise {
        // The mirror about the tool frame's xz plane: a force's y and a moment's x and z
        // (a pseudovector) turn sign.
        f_tool.y = -f_tool.y;
        m_tool.x = -m_tool.x;
        m_tool.z = -m_tool.z;
    }
    let (f, m) = (frame * f_tool, frame * m_tool);
    let w = Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
    crate::error::check_output("cutting wrench", w.as_slice())?;
    Ok((f, w))
}

/// Feed per tooth \[m\] of `setup`'s tool at a path sample: horizontal speed over spindle
/// speed times flutes (0 at rest or with the spindle off).
pub fn feed_per_tooth(setup: &Setup, s: &PathSample) -> f64 {
    tooth_feed(&setup.tool, s, s.spindle)
}

/// [`feed_per_tooth`] of `tool` at spindle speed `spindle` \[rev/s\] (either sign).
fn tooth_feed(tool: &Tool, s: &PathSample, spindle: f64) -> f64 {
    let v = s.speed * s.direction.xy().norm();
    let teeth = spindle.abs() * f64::from(tool.flutes);
    if teeth > 0.0 { v / teeth } else { 0.0 }
}

/// One tool of the program as the pass uses it: its cutter, probes and force weights, built
/// once per run, and whether the job knows it (else the setup's tool stands in, and cutting
/// with it is an error).
#[derive(Debug, Clone)]
struct ToolModel {
    number: u32,
    tool: Tool,
    cutter: Cutter,
    probes: engagement::Probes,
    chip: ChipModel,
    known: bool,
}

/// The tools a program uses, in the order of their numbers.
#[derive(Debug, Clone)]
struct ToolModels {
    list: Vec<ToolModel>,
}

impl ToolModels {
    fn new(job: &Job, program: &Program) -> Self {
        let setup = &job.setup;
        let mut list: Vec<ToolModel> = Vec::new();
        for number in program.tools() {
            let found = job.tool(number);
            let (tool, cutter) = found.unwrap_or((
                setup.tool,
                Cutter::Flat {
                    radius: 0.5 * setup.tool.diameter,
                },
            ));
            let probes = engagement::Probes::new(cutter.radius(), setup.stock.cell);
            let count = probes.count();
            list.push(ToolModel {
                number,
                tool,
                cutter,
                probes,
                chip: ChipModel::new(&setup.coefficients, &tool, count),
                known: found.is_some(),
            });
        }
        Self { list }
    }

    /// The index of tool `number` (the program's tools are all listed; 0 otherwise).
    fn find(&self, number: u32) -> usize {
        self.list
            .iter()
            .position(|t| t.number == number)
            .unwrap_or(0)
    }

    fn get(&self, index: usize) -> Option<&ToolModel> {
        self.list.get(index)
    }
}

fn in_limits(q: &[f64], limits: &[(f64, f64)]) -> Result<(), TickError> {
    crate::mechanism::check_limits(q, limits, JOINT_LIMIT_TOLERANCE)
}

/// A wrench `[f; m]` turned by the rotation of `t` (the moment point moves with it).
pub(crate) fn rotate(t: &Isometry3<f64>, w: &Vector6) -> Vector6 {
    let f = t.rotation * w.fixed_rows::<3>(0).into_owned();
    let m = t.rotation * w.fixed_rows::<3>(3).into_owned();
    Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
}

/// The z-map pass runs 2.5-D programs: a tool axis off the workpiece +z would be silently
/// dropped by it ([`crate::machining::five_axis`] runs the others).
pub(crate) fn check_flat(program: &Program) -> Result<(), BuildError> {
    use crate::machining::program::angle_between;
    let z = Vector3::z();
    if let Some((index, m)) = program
        .moves
        .iter()
        .enumerate()
        .find(|(_, m)| m.start_axis != z || m.end_axis != z)
    {
        return Err(BuildError::InvalidEntry {
            what: "program moves (index: the move; value: its tool axis' angle from +z, rad)",
            index,
            value: angle_between(&m.end_axis, &z).max(angle_between(&m.start_axis, &z)),
            expected: "a tool axis along the workpiece +z: the z-map job runs 2.5-D programs \
                       (machining::five_axis runs five-axis ones)",
        });
    }
    Ok(())
}

/// Seed joints, one per joint of the job's arm.
pub(crate) fn check_seed(job: &Job, seed: &[f64]) -> Result<(), BuildError> {
    let dof = job.model.dof();
    if seed.len() != dof {
        return Err(BuildError::WrongLength {
            what: "seed joints",
            expected: dof,
            got: seed.len(),
        });
    }
    Ok(())
}

/// A cell as wide as a tool's radius cannot resolve its cut (a stock of one cell reads every
/// error as 0): at most half the radius of every tool the program uses.
fn check_cell(st: &Stock, tools: &ToolModels) -> Result<(), BuildError> {
    if let Some(t) = tools
        .list
        .iter()
        .find(|t| st.cell > 0.5 * t.cutter.radius())
    {
        return Err(BuildError::InvalidParameter {
            what: "stock cell (m), at most half the radius of every tool the program uses",
            value: st.cell,
            expected: if t.known {
                "<= the radius / 2 of the program's smallest tool"
            } else {
                "<= the job's tool radius / 2"
            },
        });
    }
    Ok(())
}
