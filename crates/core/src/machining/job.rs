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
//! The tool axis is the workpiece's z (a 2.5-D program in G17); the deflected tool's tilt
//! (milliradians) is not carried into the z-maps.

use alloc::vec::Vec;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::Program;
use super::cutting::{self, Coefficients, Engagement, Tool};
use super::engagement::{self, Contact};
use super::path::{self, PathOptions, PathSample};
use super::stock::{Cutter, ZMap};
use crate::error::{BuildError, JobError, TickError};
use crate::mechanism::{PoseIkOptions, pose_ik};
use crate::vjm::{self, Data, Load, MAX_DOF, Model, Vector6};

/// Slack on the joint limits \[rad or m\]: a pose IK solution that rounding puts this far past
/// a limit still counts as inside.
pub const JOINT_LIMIT_TOLERANCE: f64 = 1.0e-9;

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
        self.ik.validate()
    }
}

/// The arm, its joint limits and the job's setup: immutable once built.
#[derive(Debug, Clone)]
pub struct Job {
    model: Model,
    limits: Vec<(f64, f64)>,
    setup: Setup,
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
        })
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

/// One sample of the offline pass. Positions and forces in the workpiece frame unless said.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JobSample {
    /// The programmed tool at this sample.
    pub path: PathSample,
    /// Where the nominal tool meets the nominal stock.
    pub contact: Contact,
    /// Feed per tooth \[m\] (horizontal speed / (spindle speed x flutes); 0 at rest).
    pub feed_per_tooth: f64,
    /// Per-revolution force on the tool from the nominal cut \[N\], workpiece frame.
    pub force: Vector3<f64>,
    /// The wrench on the TCP \[N, N m\], base frame, moment about the tip: what the
    /// compensation is computed for.
    pub wrench: Vector6,
    /// Rigid pose-IK joints of the programmed pose \[rad or m\]; entries past the dof are 0.
    pub q: [f64; MAX_DOF],
    /// Deflection `[dp; dr]` of the tip at `q` under `wrench` \[m, rad\], base frame.
    pub deflection: Vector6,
    /// Compensated joints: the loaded tip reaches the programmed pose \[rad or m\].
    pub q_commanded: [f64; MAX_DOF],
    /// The Cartesian command: the rigid pose at `q_commanded`, workpiece frame.
    pub commanded: Isometry3<f64>,
    /// Predicted tip without compensation \[m\].
    pub actual_uncompensated: Vector3<f64>,
    /// Force the uncompensated tool feels where it is \[N\].
    pub force_uncompensated: Vector3<f64>,
    /// Predicted tip with compensation \[m\].
    pub actual_compensated: Vector3<f64>,
}

/// Largest and root-mean-square values of a deviation \[m\].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorStats {
    /// Largest magnitude \[m\].
    pub max: f64,
    /// Root mean square \[m\].
    pub rms: f64,
    /// Entries counted.
    pub count: usize,
}

impl ErrorStats {
    fn of(values: impl Iterator<Item = f64>) -> Self {
        let (mut s, mut n, mut m) = (0.0, 0usize, 0.0f64);
        for v in values {
            s += v * v;
            n += 1;
            m = m.max(v.abs());
        }
        Self {
            max: m,
            rms: if n > 0 {
                nalgebra::ComplexField::sqrt(s / n as f64)
            } else {
                0.0
            },
            count: n,
        }
    }
}

/// A predicted part against the nominal one ([`Report::surface_error`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfaceError {
    /// Height above the nominal part over the cells both cut \[m\] (> 0: material left).
    pub floor: ErrorStats,
    /// Area the nominal part has cut and the predicted one not \[m^2\].
    pub material_left: f64,
    /// Area the predicted part has cut and the nominal one not \[m^2\].
    pub overcut: f64,
}

/// Force statistics of one program line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineForce {
    /// Program line.
    pub line: usize,
    /// Samples on it.
    pub samples: usize,
    /// Mean force on the tool \[N\], workpiece frame.
    pub mean: Vector3<f64>,
    /// Largest force magnitude \[N\].
    pub max: f64,
}

/// What the offline pass predicts.
#[derive(Debug, Clone)]
pub struct Report {
    /// Every sample, in time order.
    pub samples: Vec<JobSample>,
    /// The part as programmed.
    pub nominal: ZMap,
    /// The part the uncompensated arm cuts.
    pub uncompensated: ZMap,
    /// The part the compensated arm cuts.
    pub compensated: ZMap,
    /// Samples that plunge into material (feed along the tool axis): no side-milling force.
    pub plunge_samples: usize,
    /// Z-map cells lowered over the three stocks (the material removal's work).
    pub cell_updates: usize,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
    /// Joints of the arm.
    pub dof: usize,
    /// The stock's top \[m\].
    pub top: f64,
}

impl Report {
    /// Distance of the predicted tip from the programmed one over the feed moves \[m\]:
    /// `compensated` false for the uncompensated arm.
    pub fn path_error(&self, compensated: bool) -> ErrorStats {
        ErrorStats::of(self.samples.iter().filter(|s| s.path.feed_move).map(|s| {
            let a = if compensated {
                s.actual_compensated
            } else {
                s.actual_uncompensated
            };
            (a - s.path.position).norm()
        }))
    }

    /// A predicted part against the nominal one: the floors (cells both cut, by more than
    /// [`super::engagement::MIN_DEPTH`]: height above the nominal, > 0 where material is
    /// left), and the walls' shift as the areas cut by one and not the other \[m^2\] (a
    /// height map sees a wall moved sideways as a full-depth step; the areas measure it).
    pub fn surface_error(&self, predicted: &ZMap) -> SurfaceError {
        let cut = |h: f64| h < self.top - super::engagement::MIN_DEPTH;
        let area = self.nominal.cell() * self.nominal.cell();
        let (mut left, mut over) = (0usize, 0usize);
        let floor = ErrorStats::of(
            self.nominal
                .heights()
                .iter()
                .zip(predicted.heights())
                .filter_map(|(&n, &p)| match (cut(n), cut(p)) {
                    (true, true) => Some(p - n),
                    (true, false) => {
                        left += 1;
                        None
                    }
                    (false, true) => {
                        over += 1;
                        None
                    }
                    (false, false) => None,
                }),
        );
        SurfaceError {
            floor,
            material_left: left as f64 * area,
            overcut: over as f64 * area,
        }
    }

    /// The pilot-control signal of the annotated program (sec. 2.3 of Hähn and Weigold): the
    /// TCP wrench at each sample's time plus `lead` \[s\] (the paper's program carried its
    /// forces 40 ms early), the last wrench held at the end. `lead` is rounded to samples;
    /// negative or non-finite leads count as 0.
    pub fn pilot_wrenches(&self, lead: f64) -> Vec<Vector6> {
        let shift = if lead.is_finite() && lead > 0.0 {
            nalgebra::ComplexField::round(lead * self.rate_hz).min(usize::MAX as f64) as usize
        } else {
            0
        };
        let n = self.samples.len();
        (0..n)
            .filter_map(|k| {
                self.samples
                    .get(k.saturating_add(shift).min(n.saturating_sub(1)))
                    .map(|s| s.wrench)
            })
            .collect()
    }

    /// The force per program line (lines with samples, in program order of first sample).
    pub fn line_forces(&self) -> Vec<LineForce> {
        let mut out: Vec<LineForce> = Vec::new();
        for s in &self.samples {
            match out.last_mut() {
                Some(l) if l.line == s.path.line => {
                    l.samples += 1;
                    l.mean += s.force;
                    l.max = l.max.max(s.force.norm());
                }
                _ => out.push(LineForce {
                    line: s.path.line,
                    samples: 1,
                    mean: s.force,
                    max: s.force.norm(),
                }),
            }
        }
        for l in &mut out {
            l.mean /= l.samples as f64;
        }
        out
    }
}

/// The force on the tool (workpiece frame) and the wrench about the tip (workpiece frame)
/// for a contact: each engaged arc's per-revolution force acting at half its depth up the
/// axis, plus the cutting torque about the axis; zero in air and for plunges.
fn cut_force(
    setup: &Setup,
    contact: &Contact,
    sample: &PathSample,
    feed_per_tooth: f64,
) -> Result<(Vector3<f64>, Vector6), TickError> {
    let Some(frame) = cutting::tool_frame(&Vector3::z(), &sample.direction) else {
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
        let f = cutting::average(&setup.coefficients, &setup.tool, &e)?;
        let torque = cutting::average_torque(&setup.coefficients, &setup.tool, &e)?;
        m_tool += Vector3::new(0.0, 0.0, 0.5 * arc.depth).cross(&f) + Vector3::z() * torque;
        f_tool += f;
    }
    let (f, m) = (frame * f_tool, frame * m_tool);
    Ok((f, Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)))
}

fn feed_per_tooth(setup: &Setup, s: &PathSample) -> f64 {
    let v = s.speed * s.direction.xy().norm();
    let teeth = s.spindle * f64::from(setup.tool.flutes);
    if teeth > 0.0 { v / teeth } else { 0.0 }
}

fn in_limits(q: &[f64], limits: &[(f64, f64)]) -> Result<(), TickError> {
    for (joint, (&value, &(lower, upper))) in q.iter().zip(limits).enumerate() {
        if !(value >= lower - JOINT_LIMIT_TOLERANCE && value <= upper + JOINT_LIMIT_TOLERANCE) {
            return Err(TickError::JointLimit {
                joint,
                value,
                lower,
                upper,
            });
        }
    }
    Ok(())
}

/// Runs the offline pass (see the module docs) from the joints `seed` near the first pose
/// (they choose the IK branch). Errors name the program line.
pub fn run(job: &Job, program: &Program, seed: &[f64]) -> Result<Report, JobError> {
    let setup = &job.setup;
    let model = &job.model;
    let dof = model.dof();
    let st = &setup.stock;
    let zmap = || ZMap::new(st.min, st.max, st.top, st.cell);
    let (mut nominal, mut unc, mut comp) = (zmap()?, zmap()?, zmap()?);
    let path = path::sample(program, &setup.path)?;
    let cutter = Cutter::Flat {
        radius: 0.5 * setup.tool.diameter,
    };
    let radius = cutter.radius();
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
    let (mut prev_nom, mut prev_unc, mut prev_comp): (
        Option<Vector3<f64>>,
        Vector3<f64>,
        Vector3<f64>,
    ) = (None, Vector3::zeros(), Vector3::zeros());
    for s in &path {
        let at = |error: TickError| JobError::AtLine {
            line: s.line,
            time: s.time,
            error,
        };
        let p = s.position;
        let from = prev_nom.unwrap_or(p);
        // 2. The nominal contact, checked before the cut lowers the stock.
        let contact = engagement::contact(&nominal, radius, &p, &s.direction);
        let removed = nominal.cut(&cutter, &from, &p).map_err(at)?;
        if !s.feed_move {
            let area = st.cell * st.cell;
            if removed.cells > 0
                && removed.volume > removed.cells as f64 * area * engagement::MIN_DEPTH
            {
                return Err(JobError::RapidInStock {
                    line: s.line,
                    time: s.time,
                    depth: removed.volume / (removed.cells as f64 * area),
                });
            }
        }
        if contact != Contact::Air && s.spindle <= 0.0 {
            return Err(JobError::SpindleOff {
                line: s.line,
                time: s.time,
            });
        }
        if matches!(contact, Contact::Plunge { .. }) {
            plunge_samples += 1;
        }
        let fz = feed_per_tooth(setup, s);
        let (force, wrench_w) = cut_force(setup, &contact, s, fz).map_err(at)?;
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
        let step = p - from;
        let probe_unc = if prev_nom.is_some() {
            prev_unc + step
        } else {
            p
        };
        let c_unc = engagement::contact(&unc, radius, &probe_unc, &s.direction);
        let (force_unc, w_unc) = cut_force(setup, &c_unc, s, fz).map_err(at)?;
        let d_unc = vjm::deflection(
            model,
            &mut data,
            q.get(..dof).unwrap_or(&[]),
            &rotate(&to_base, &w_unc),
            Load::Exact,
        )
        .map_err(at)?;
        let actual_unc =
            to_work * Point3::from(target.translation.vector + d_unc.fixed_rows::<3>(0));
        let probe_comp = if prev_nom.is_some() {
            prev_comp + step
        } else {
            p
        };
        let c_comp = engagement::contact(&comp, radius, &probe_comp, &s.direction);
        let (_, w_comp) = cut_force(setup, &c_comp, s, fz).map_err(at)?;
        vjm::deflection(
            model,
            &mut data,
            qc.get(..dof).unwrap_or(&[]),
            &rotate(&to_base, &w_comp),
            Load::Exact,
        )
        .map_err(at)?;
        let actual_comp = to_work * Point3::from(data.tcp_deflected.translation.vector);
        let (actual_unc, actual_comp) = (actual_unc.coords, actual_comp.coords);
        let r_unc = unc
            .cut(
                &cutter,
                &prev_nom.map_or(actual_unc, |_| prev_unc),
                &actual_unc,
            )
            .map_err(at)?;
        let r_comp = comp
            .cut(
                &cutter,
                &prev_nom.map_or(actual_comp, |_| prev_comp),
                &actual_comp,
            )
            .map_err(at)?;
        cell_updates += removed.cells + r_unc.cells + r_comp.cells;
        prev_nom = Some(p);
        prev_unc = actual_unc;
        prev_comp = actual_comp;
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
        nominal,
        uncompensated: unc,
        compensated: comp,
        plunge_samples,
        cell_updates,
        rate_hz: setup.path.rate_hz,
        dof,
        top: st.top,
    })
}

/// A wrench `[f; m]` turned by the rotation of `t` (the moment point moves with it).
fn rotate(t: &Isometry3<f64>, w: &Vector6) -> Vector6 {
    let f = t.rotation * w.fixed_rows::<3>(0).into_owned();
    let m = t.rotation * w.fixed_rows::<3>(3).into_owned();
    Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
}
