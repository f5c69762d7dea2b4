//! The offline pass of the hybrid compensation of Hähn and Weigold (2020, sec. 2.3-2.4) over a
//! user's program: the program driven at its feeds ([`super::path`]), the stock cut along it
//! ([`super::stock`]) with the engagement read at every sample ([`super::engagement`]), the
//! mechanistic per-revolution force ([`super::cutting::average`]) turned into the TCP wrench,
//! the exact virtual-joint deflection (Eq. 2-9 of the paper) at the rigid pose-IK joints, and
//! the compensated joints at which the *loaded* arm lands on the programmed pose.
//!
//! Per sample (workpiece frame `W`, placed at [`Setup::placement`] in the base frame):
//!
//! 1. the programmed tool tip `p`, its target pose `placement * (p, tool_orientation)`, and
//!    the rigid joints `q` by pose IK from the previous sample's (the first from the seed);
//! 2. the contact of the nominal tool with the nominal stock, the force `F` on the tool and
//!    the wrench about the tip: `F` acting at half the depth up the tool axis and the cutting
//!    torque about the axis ([`super::cutting::average_torque`]);
//! 3. the deflection of the tip under that wrench at `q` (exact VJM), and the compensated
//!    joints `q_c` at which the loaded tip reaches the target (pose IK of the loaded chain);
//!    the Cartesian command is the rigid pose at `q_c`, the axis-specific one `q_c - q`;
//! 4. the part, predicted three ways on three z-maps: nominal (the tool on the program),
//!    uncompensated (at `q`) and compensated (at `q_c`). The two predictions feel the force of
//!    the tool where it is, not where it was programmed: the engagement is read on their own
//!    stock at the tip position of the previous sample plus this sample's programmed step
//!    (one sample of lag at 250 Hz-2 kHz), so a deflected tool cuts shallower and feels
//!    less force, as on the robot.
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

use alloc::vec::Vec;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::Program;
use super::cutting::{self, Coefficients, Engagement, Tool};
use super::engagement::{self, Contact};
use super::path::{self, PathOptions, PathSample};
pub use super::report::{ErrorStats, JobSample, LineForce, RapidContact, Report, SurfaceError};
use super::stock::{Cutter, Removal, ZMap};
use super::tools::ToolTable;
use crate::error::{BuildError, JobError, TickError};
use crate::mechanism::{PoseIkOptions, pose_ik};
use crate::vjm::{self, Data, Load, MAX_DOF, Model, Vector6};

pub use crate::mechanism::JOINT_LIMIT_TOLERANCE;

/// How deep a rapid move (`G0`) may run into the predicted stock before the job refuses it
/// as a crash \[m\], by default ([`Setup::rapid_skim`]): 0.1 mm. The stops between runs are
/// sampled at the controller rate, so the predicted floor where a cut stopped may stand a few
/// micrometres above the programmed one (tens at 125 Hz), and CAM programs rapid down to the
/// last cut's depth.
pub const RAPID_SKIM: f64 = 1.0e-4;

/// The stock: a block over `[min, max]` (x, y) with its top at `top`, workpiece frame \[m\],
/// resolved in square cells of `cell` \[m\] (see [`super::stock::MAX_CELLS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stock {
    /// Lower corner (x, y) \[m\].
    pub min: Vector2<f64>,
    /// Upper corner (x, y) \[m\].
    pub max: Vector2<f64>,
    /// Top face height \[m\].
    pub top: f64,
    /// Cell edge \[m\].
    pub cell: f64,
}

/// Everything about a job but the arm and the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// The workpiece frame in the robot's base frame.
    pub placement: Isometry3<f64>,
    /// The TCP frame's orientation in the workpiece frame; its z axis must lie along the
    /// workpiece's z (either way: the tool axis of a 2.5-D program).
    pub tool_orientation: UnitQuaternion<f64>,
    /// The end mill (a flat end mill of its diameter).
    pub tool: Tool,
    /// The material's cutting and edge coefficients.
    pub coefficients: Coefficients,
    /// The block the part is cut from.
    pub stock: Stock,
    /// How the program is driven and sampled.
    pub path: PathOptions,
    /// Pose IK settings (rigid and loaded).
    pub ik: PoseIkOptions,
    /// Speed of a spindle the program does not start \[rev/s\] (a hand-started spindle: posts
    /// for such machines write no `M3`): it turns clockwise at this speed wherever the
    /// program's spindle is off. `None`: the program's spindle only.
    pub hand_spindle: Option<f64>,
    /// How deep a rapid move may run into the predicted stock \[m\] before the job refuses
    /// it ([`JobError::RapidInStock`]); the deepest contact within it is reported
    /// ([`Report::rapid_contact`]). Default [`RAPID_SKIM`].
    pub rapid_skim: f64,
}

impl Setup {
    /// The TCP's z axis pointing down the workpiece z (out of the flange, into the part) and
    /// its x along the workpiece x: a rotation of pi about x.
    pub fn tool_down() -> UnitQuaternion<f64> {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), core::f64::consts::PI)
    }

    /// Checks the placement, stock (its cell budget, without allocating), tool,
    /// coefficients, path and IK options.
    pub fn validate(&self) -> Result<(), BuildError> {
        let t = &self.placement;
        if let Some(index) = t
            .translation
            .vector
            .iter()
            .chain(t.rotation.coords.iter())
            .position(|v| !v.is_finite())
        {
            return Err(BuildError::NonFinite {
                what: "placement (x, y, z, then quaternion i, j, k, w)",
                index,
            });
        }
        let z = self.tool_orientation * Vector3::z();
        crate::error::param(
            "tool orientation (|z_tcp . z_workpiece|, must be 1)",
            z.z.abs(),
            (z.z.abs() - 1.0).abs() <= 1.0e-6,
            "the TCP z axis along the workpiece z (2.5-D program)",
        )?;
        let st = &self.stock;
        ZMap::shape_for(st.min, st.max, st.top, st.cell)?;
        self.tool.validate()?;
        self.coefficients.validate()?;
        self.path.validate()?;
        crate::error::param(
            "rapid skim (m)",
            self.rapid_skim,
            self.rapid_skim.is_finite() && (0.0..=0.1).contains(&self.rapid_skim),
            "in [0, 0.1] m",
        )?;
        if let Some(v) = self.hand_spindle {
            crate::error::param(
                "hand spindle speed (rev/s)",
                v,
                v > 0.0 && v <= super::MAX_SPINDLE_RPM / 60.0,
                "in (0, MAX_SPINDLE_RPM / 60] rev/s",
            )?;
        }
        self.ik.validate()
    }
}

/// The arm, its joint limits and the job's setup: immutable once built.
#[derive(Debug, Clone)]
pub struct Job {
    model: Model,
    limits: Vec<(f64, f64)>,
    setup: Setup,
    tools: Option<ToolTable>,
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
        })
    }

    /// The job with a tool table: each move cuts with the tool its program line put in the
    /// spindle (a program's `T` missing from the table is an error where that tool cuts).
    #[must_use]
    pub fn with_tools(mut self, tools: ToolTable) -> Self {
        self.tools = Some(tools);
        self
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

/// The force on the tool \[N\] and the wrench about the tip \[N, N m\] (both workpiece
/// frame) of a contact of `setup`'s tool, turning clockwise, moving along `feed` (workpiece
/// frame, any length): [`tool_wrench`] with the setup's tool and material. What a simulation
/// calls with the contact where its tool really is.
pub fn contact_wrench(
    setup: &Setup,
    contact: &Contact,
    feed: &Vector3<f64>,
    feed_per_tooth: f64,
) -> Result<(Vector3<f64>, Vector6), TickError> {
    tool_wrench(
        &setup.coefficients,
        &setup.tool,
        contact,
        feed,
        feed_per_tooth,
        false,
    )
}

/// The force on the tool \[N\] and the wrench about the tip \[N, N m\] (both workpiece
/// frame) of `tool` in `contact`, moving along `feed` (workpiece frame, any length): each
/// engaged arc's per-revolution force acting at half its depth up the axis, plus the cutting
/// torque about the axis; zero in air, for plunges and without a horizontal feed. A
/// `counter_clockwise` spindle (`M4`; its contact read by [`engagement::contact_turning`])
/// gives the mirror image about the feed direction: the lateral force and the torques turn
/// sign.
pub fn tool_wrench(
    coefficients: &Coefficients,
    tool: &Tool,
    contact: &Contact,
    feed: &Vector3<f64>,
    feed_per_tooth: f64,
    counter_clockwise: bool,
) -> Result<(Vector3<f64>, Vector6), TickError> {
    let Some(frame) = cutting::tool_frame(&Vector3::z(), feed) else {
        return Ok((Vector3::zeros(), Vector6::zeros()));
    };
    let (mut f_tool, mut m_tool) = (Vector3::zeros(), Vector3::zeros());
    for arc in contact.arcs() {
        let e = Engagement {
            entry: arc.entry,
            exit: arc.exit,
            depth: arc.depth,
            feed_per_tooth,
        };
        let f = cutting::average(coefficients, tool, &e)?;
        let torque = cutting::average_torque(coefficients, tool, &e)?;
        m_tool += Vector3::new(0.0, 0.0, 0.5 * arc.depth).cross(&f) + Vector3::z() * torque;
        f_tool += f;
    }
    if counter_clockwise {
        // The mirror about the tool frame's xz plane: a force's y and a moment's x and z
        // (a pseudovector) turn sign.
        f_tool.y = -f_tool.y;
        m_tool.x = -m_tool.x;
        m_tool.z = -m_tool.z;
    }
    let (f, m) = (frame * f_tool, frame * m_tool);
    Ok((f, Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)))
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

fn in_limits(q: &[f64], limits: &[(f64, f64)]) -> Result<(), TickError> {
    crate::mechanism::check_limits(q, limits, JOINT_LIMIT_TOLERANCE)
}

/// Runs the offline pass (see the module docs) from the joints `seed` near the first pose
/// (they choose the IK branch). Errors name the program line.
pub fn run(job: &Job, program: &Program, seed: &[f64]) -> Result<Report, JobError> {
    let setup = &job.setup;
    let model = &job.model;
    let dof = model.dof();
    let st = &setup.stock;
    let zmap = || ZMap::new(st.min, st.max, st.top, st.cell);
    let mut nominal = zmap()?;
    let (mut unc, mut comp) = (Predicted::new(zmap()?), Predicted::new(zmap()?));
    let path = path::sample(program, &setup.path)?;
    let mut samples = Vec::new();
    samples
        .try_reserve_exact(path.len())
        .map_err(|_| BuildError::Budget {
            what: "job samples (the allocation was refused)",
            budget: "MAX_PATH_SAMPLES",
            limit: path::MAX_PATH_SAMPLES,
            requested: path.len(),
        })?;
    let mut data = Data::new(model);
    let mut q = [0.0; MAX_DOF];
    match q.get_mut(..dof) {
        Some(head) if seed.len() == dof => head.copy_from_slice(seed),
        _ => {
            return Err(BuildError::WrongLength {
                what: "seed joints",
                expected: dof,
                got: seed.len(),
            }
            .into());
        }
    }
    let mut qc = q;
    let to_base = setup.placement;
    let to_work = to_base.inverse();
    let (mut plunge_samples, mut cell_updates) = (0, 0);
    let mut prev_nom: Option<Vector3<f64>> = None;
    let frame = Frame {
        job,
        to_base,
        to_work,
    };
    let mut spindle_tool = SpindleTool::default();
    let mut rapid_contact: Option<RapidContact> = None;
    for s in &path {
        let at = |error: TickError| JobError::AtLine {
            line: s.line,
            time: s.time,
            error,
        };
        let p = s.position;
        let from = prev_nom.unwrap_or(p);
        let (tool, cutter, known) = spindle_tool.at(job, s.tool);
        let spindle = match (s.spindle, setup.hand_spindle) {
            (0.0, Some(hand)) => hand,
            (v, _) => v,
        };
        let ccw = spindle < 0.0;
        // 2. The nominal contact, checked before the cut lowers the stock.
        let contact = engagement::contact_turning(&nominal, cutter.radius(), &p, &s.direction, ccw);
        let removed = nominal.cut(&cutter, &from, &p).map_err(at)?;
        let cut = NominalCut {
            contact: &contact,
            removed: &removed,
            known,
            spindle,
        };
        cut.check(setup, s, &mut rapid_contact)?;
        if matches!(contact, Contact::Plunge { .. }) {
            plunge_samples += 1;
        }
        let fz = tooth_feed(&tool, s, spindle);
        let (force, wrench_w) =
            tool_wrench(&setup.coefficients, &tool, &contact, &s.direction, fz, ccw).map_err(at)?;
        let wrench = rotate(&to_base, &wrench_w);
        // 1. The programmed pose and its rigid joints.
        let target = to_base * Isometry3::from_parts(Translation3::from(p), setup.tool_orientation);
        let zero = Vector6::zeros();
        let rigid = pose_ik(
            model,
            &mut data,
            &target,
            q.get(..dof).unwrap_or(&[]),
            &zero,
            Load::Rigid,
            &setup.ik,
        )
        .map_err(at)?;
        q = rigid.q;
        in_limits(q.get(..dof).unwrap_or(&[]), &job.limits).map_err(at)?;
        // 3. The deflection and the compensated joints.
        let deflection = vjm::deflection(
            model,
            &mut data,
            q.get(..dof).unwrap_or(&[]),
            &wrench,
            Load::Exact,
        )
        .map_err(at)?;
        let loaded = pose_ik(
            model,
            &mut data,
            &target,
            qc.get(..dof).unwrap_or(&[]),
            &wrench,
            Load::Exact,
            &setup.ik,
        )
        .map_err(at)?;
        qc = loaded.q;
        in_limits(qc.get(..dof).unwrap_or(&[]), &job.limits).map_err(at)?;
        let commanded = to_work * data.tcp;
        // 4. The predictions: the force where each tool is (lagged one sample), its
        // deflection, its cut.
        let tick = Tick {
            sample: s,
            step: p - from,
            feed_per_tooth: fz,
            tool,
            cutter,
            counter_clockwise: ccw,
        };
        let q_rigid = q.get(..dof).unwrap_or(&[]);
        let (force_unc, actual_unc, r_unc) =
            unc.advance(&frame, &mut data, q_rigid, &tick).map_err(at)?;
        let q_comp = qc.get(..dof).unwrap_or(&[]);
        let (_, actual_comp, r_comp) =
            comp.advance(&frame, &mut data, q_comp, &tick).map_err(at)?;
        cell_updates += removed.cells + r_unc + r_comp;
        prev_nom = Some(p);
        samples.push(JobSample {
            path: *s,
            contact,
            feed_per_tooth: fz,
            force,
            wrench,
            q,
            deflection,
            q_commanded: qc,
            commanded,
            actual_uncompensated: actual_unc,
            force_uncompensated: force_unc,
            actual_compensated: actual_comp,
        });
    }
    Ok(Report {
        samples,
        rapid_contact,
        nominal,
        uncompensated: unc.stock,
        compensated: comp.stock,
        plunge_samples,
        cell_updates,
        rate_hz: setup.path.rate_hz,
        dof,
        top: st.top,
    })
}

/// The tool in the spindle, looked up once per change: its cutter, and whether the job
/// knows it (else the setup's tool stands in, and cutting with it is an error).
#[derive(Default)]
struct SpindleTool {
    last: Option<(u32, Option<(Tool, Cutter)>)>,
}

impl SpindleTool {
    fn at(&mut self, job: &Job, t: u32) -> (Tool, Cutter, bool) {
        let found = match self.last {
            Some((n, found)) if n == t => found,
            _ => {
                let found = job.tool(t);
                self.last = Some((t, found));
                found
            }
        };
        let stand_in = job.setup.tool;
        let (tool, cutter) = found.unwrap_or((
            stand_in,
            Cutter::Flat {
                radius: 0.5 * stand_in.diameter,
            },
        ));
        (tool, cutter, found.is_some())
    }
}

/// The nominal cut of one sample, checked: a tool the job lacks must not cut, a rapid may
/// skim the stock by `rapid_skim` (the deepest skim kept), the spindle must turn in a cut.
struct NominalCut<'a> {
    contact: &'a Contact,
    removed: &'a Removal,
    known: bool,
    spindle: f64,
}

impl NominalCut<'_> {
    fn check(
        &self,
        setup: &Setup,
        s: &PathSample,
        rapid_contact: &mut Option<RapidContact>,
    ) -> Result<(), JobError> {
        let (line, time) = (s.line, s.time);
        let cuts = *self.contact != Contact::Air;
        if !self.known && (cuts || self.removed.cells > 0) {
            return Err(JobError::UnknownTool {
                line,
                time,
                tool: s.tool,
            });
        }
        let depth = self.removed.deepest;
        if !s.feed_move && depth > engagement::MIN_DEPTH {
            if rapid_contact.is_none_or(|c| depth > c.depth) {
                *rapid_contact = Some(RapidContact { line, time, depth });
            }
            if depth > setup.rapid_skim {
                return Err(JobError::RapidInStock { line, time, depth });
            }
        }
        if cuts && self.spindle == 0.0 {
            return Err(JobError::SpindleOff { line, time });
        }
        Ok(())
    }
}

/// What every prediction shares: the job and the frames.
struct Frame<'a> {
    job: &'a Job,
    to_base: Isometry3<f64>,
    to_work: Isometry3<f64>,
}

/// One sample as a prediction sees it: the programmed sample, the programmed step since the
/// last one \[m\], the feed per tooth \[m\], the tool in the spindle and its direction.
struct Tick<'a> {
    sample: &'a PathSample,
    step: Vector3<f64>,
    feed_per_tooth: f64,
    tool: Tool,
    cutter: Cutter,
    counter_clockwise: bool,
}

/// One predicted arm (uncompensated or compensated): its own stock and where its tool is.
struct Predicted {
    stock: ZMap,
    tip: Option<Vector3<f64>>,
}

impl Predicted {
    fn new(stock: ZMap) -> Self {
        Self { stock, tip: None }
    }

    /// The arm at joints `q` for one sample: the force where its tool is (its last tip plus
    /// the programmed step), the deflected tip under that force, the cut to it. Returns the
    /// force \[N\] and the tip \[m\] (workpiece frame) and the cells lowered.
    fn advance(
        &mut self,
        f: &Frame<'_>,
        data: &mut Data,
        q: &[f64],
        t: &Tick<'_>,
    ) -> Result<(Vector3<f64>, Vector3<f64>, usize), TickError> {
        let s = t.sample;
        let probe = self.tip.map_or(s.position, |tip| tip + t.step);
        let radius = t.cutter.radius();
        let contact = engagement::contact_turning(
            &self.stock,
            radius,
            &probe,
            &s.direction,
            t.counter_clockwise,
        );
        let (force, wrench) = tool_wrench(
            &f.job.setup.coefficients,
            &t.tool,
            &contact,
            &s.direction,
            t.feed_per_tooth,
            t.counter_clockwise,
        )?;
        vjm::deflection(
            &f.job.model,
            data,
            q,
            &rotate(&f.to_base, &wrench),
            Load::Exact,
        )?;
        let tip = (f.to_work * Point3::from(data.tcp_deflected.translation.vector)).coords;
        let removed = self.stock.cut(&t.cutter, &self.tip.unwrap_or(tip), &tip)?;
        self.tip = Some(tip);
        Ok((force, tip, removed.cells))
    }
}

/// A wrench `[f; m]` turned by the rotation of `t` (the moment point moves with it).
fn rotate(t: &Isometry3<f64>, w: &Vector6) -> Vector6 {
    let f = t.rotation * w.fixed_rows::<3>(0).into_owned();
    let m = t.rotation * w.fixed_rows::<3>(3).into_owned();
    Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
}
