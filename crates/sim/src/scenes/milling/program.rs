//! The paper's validation on a program (Hähn and Weigold 2020, sec. 3): the flexible KR 300
//! follows a machining program sample by sample (4 ms cycles, 0.5 ms physics), and at every
//! physics step the force on the tool is the mechanistic model's for the engagement read from
//! the run's own z-map *where the simulated tool really is*, so a tool the force pushes away
//! cuts less, as on the robot. Runs ([`ProgramMode`]): uncompensated; the offline compensated
//! joints of deflect-core's `machining::job`; online Cartesian compensation; online Cartesian
//! with pilot control from the offline forces (hybrid); online axis-specific; hybrid with the
//! offline inertial feed-forward (combined). Each run's part is compared with the nominal one.
//!
//! The combined run adds to the hybrid one's joints, sample by sample, what the inertial loads
//! change in the offline compensated joints: the offline pass once more with the job's inertia
//! (the spindle's D'Alembert wrench and the link masses' loads in the path's planned motion,
//! `deflect_core::machining::job::Inertia`), its compensated joints less those of the pass
//! without it. The online loop goes on compensating the measured process force as the hybrid
//! run does (the simulated sensor reads the process force; the spindle's inertial force on it
//! is not simulated). With nothing to count (a massless spindle, the link loads off) the
//! feed-forward is zero and the combined run is the hybrid one bit for bit.

use deflect_core::compensation::{self, CompensatorConfig, CorrectionOutput, SensorCalibration};
use deflect_core::machining::job::{self, Job, Report, SurfaceError};
use deflect_core::machining::stock::ZMap;
use deflect_core::vjm::{Model, Vector6};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use serde::Serialize;

use super::arm::MillingArm;
use super::cycle::{CycleInputs, RunStock, correct, servo_command};
use super::options::MillingOptions;
use crate::SimError;
use crate::noise::Noise;

/// Which compensation a program run uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum ProgramMode {
    /// The program's rigid joints.
    Uncompensated,
    /// The offline compensated joints (no sensor).
    Offline,
    /// Online Cartesian compensation, measured forces only.
    Cartesian,
    /// Online Cartesian compensation with pilot control from the offline forces.
    Hybrid,
    /// Online axis-specific compensation (measured forces, pilot control).
    AxisSpecific,
    /// Hybrid, with the offline inertial feed-forward (see the module docs).
    Combined,
}

impl ProgramMode {
    /// Every mode, in the order the summary reports them.
    pub const ALL: [Self; 6] = [
        Self::Uncompensated,
        Self::Offline,
        Self::Cartesian,
        Self::Hybrid,
        Self::AxisSpecific,
        Self::Combined,
    ];

    /// Short name for topics and files.
    pub fn label(self) -> &'static str {
        match self {
            Self::Uncompensated => "uncompensated",
            Self::Offline => "offline",
            Self::Cartesian => "cartesian",
            Self::Hybrid => "hybrid",
            Self::AxisSpecific => "axis_specific",
            Self::Combined => "combined",
        }
    }
}

/// One control cycle of a program run.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ProgramSample {
    /// Time \[s\].
    pub t: f64,
    /// Program line.
    pub line: usize,
    /// Programmed tool tip, workpiece frame \[m\].
    pub nominal: [f64; 3],
    /// Simulated tool tip, workpiece frame \[m\].
    pub actual: [f64; 3],
    /// Force on the tool where it is, workpiece frame \[N\].
    pub force: [f64; 3],
    /// Axial depth of the engagement where the tool is \[m\] (0 in air).
    pub depth: f64,
    /// First entry and last exit angle of the engagement \[rad\] (0, 0 in air).
    pub angles: [f64; 2],
    /// Number of engaged arcs.
    pub arcs: usize,
    /// Distance of the tip from the programmed one across the feed \[mm\].
    pub error_mm: f64,
}

/// Path-error metrics of a program run \[mm\] over the samples in the material (feed moves
/// whose nominal tool engages the stock).
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct ProgramMetrics {
    /// Largest deviation across the feed while cutting.
    pub max_mm: f64,
    /// RMS deviation while cutting.
    pub rms_mm: f64,
    /// Largest deviation in the material while a cutter enters it (the entry phase of a
    /// [`Cut`]: the first tool radius of travel).
    pub entry_max_mm: f64,
    /// Largest deviation in the material while a cutter leaves it (the last tool radius of
    /// travel of a [`Cut`], where the force falls away).
    pub exit_max_mm: f64,
}

/// A finished program run.
#[derive(Debug, Clone)]
pub struct ProgramRun {
    /// The compensation used.
    pub mode: ProgramMode,
    /// Path errors.
    pub metrics: ProgramMetrics,
    /// The part this run cut.
    pub part: ZMap,
    /// The part against the nominal one.
    pub part_error: SurfaceError,
    /// Per-cycle log.
    pub samples: Vec<ProgramSample>,
}

/// One cut of the offline pass: the tool in the material from `entry` to `exit` \[s\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Cut {
    /// Time the tool enters the material \[s\].
    pub entry: f64,
    /// Time it leaves \[s\].
    pub exit: f64,
    /// Time the cutter takes to travel its radius at the cut's feed \[s\]: how long the
    /// engagement builds up after the entry and falls away before the exit.
    pub phase: f64,
}

/// The cuts of the offline pass with a steady part, the tool in the material at least twice
/// the entry phase (tool radius over the cut's feed): the tool grazing a wall it has cut
/// (light, intermittent engagement of the pocket's last turns) has no entry or exit whose
/// error the compensation could cause, so it is not counted as one.
pub fn cuts(offline: &Report, radius: f64) -> Vec<Cut> {
    let mut out = Vec::new();
    let mut open: Option<(f64, f64)> = None;
    for s in &offline.samples {
        let cutting = !s.contact.arcs().is_empty();
        open = match (open, cutting) {
            (None, true) => Some((s.path.time, s.path.speed)),
            (Some((t0, v)), true) => Some((t0, v.max(s.path.speed))),
            (Some((t0, v)), false) => {
                let phase = radius / v.max(f64::MIN_POSITIVE);
                if s.path.time - t0 >= 2.0 * phase {
                    out.push(Cut {
                        entry: t0,
                        exit: s.path.time,
                        phase,
                    });
                }
                None
            }
            (None, false) => None,
        };
    }
    out
}

fn metrics(samples: &[ProgramSample], cuts: &[Cut], cutting: &[bool]) -> ProgramMetrics {
    let (mut m, mut sum, mut n) = (ProgramMetrics::default(), 0.0, 0usize);
    // Only samples in the material count: the error the part keeps (after an exit the
    // path stops or retracts, and an error there cuts nothing).
    for (s, &c) in samples.iter().zip(cutting) {
        if !c {
            continue;
        }
        for cut in cuts {
            if s.t >= cut.entry && s.t <= cut.entry + cut.phase {
                m.entry_max_mm = m.entry_max_mm.max(s.error_mm);
            }
            if s.t >= cut.exit - cut.phase && s.t <= cut.exit {
                m.exit_max_mm = m.exit_max_mm.max(s.error_mm);
            }
        }
        m.max_mm = m.max_mm.max(s.error_mm);
        sum += s.error_mm * s.error_mm;
        n += 1;
    }
    m.rms_mm = (sum / n.max(1) as f64).sqrt();
    m
}

/// A wrench `[f; m]` turned by `r`.
fn rotate(r: &UnitQuaternion<f64>, w: &Vector6) -> Vector6 {
    let f = r * w.fixed_rows::<3>(0).into_owned();
    let m = r * w.fixed_rows::<3>(3).into_owned();
    Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
}

/// What a program run is given beside its mode: `job` the offline pass's setup (placement,
/// tool, material, stock, path at the control cycle), `offline` its report, `feedforward` the
/// combined run's inertial joint offsets per sample, the compensator using `model`
/// (identified stiffnesses) and `calibration` (identified sensor).
#[derive(Debug, Clone, Copy)]
pub struct RunInputs<'a> {
    /// The offline pass's job.
    pub job: &'a Job,
    /// Its report.
    pub offline: &'a Report,
    /// The inertial feed-forward per sample \[rad\] (the combined run; see the module docs).
    pub feedforward: &'a [[f64; deflect_core::vjm::MAX_DOF]],
    /// The compensator's model.
    pub model: &'a Model,
    /// The compensator's sensor calibration.
    pub calibration: &'a SensorCalibration,
}

/// One run of the program of `inputs` with `mode` on `arm`.
pub fn run_program(
    arm: &MillingArm,
    opts: &MillingOptions,
    inputs: &RunInputs<'_>,
    mode: ProgramMode,
) -> Result<ProgramRun, SimError> {
    let (job, offline, feedforward) = (inputs.job, inputs.offline, inputs.feedforward);
    let (model, calibration) = (inputs.model, inputs.calibration);
    let setup = job.setup();
    let (to_base, to_work) = (setup.placement, setup.placement.inverse());
    let dof = arm.dof();
    let first = offline
        .samples
        .first()
        .ok_or_else(|| SimError::new("program run: the offline pass has no samples"))?;
    let q_start: Vec<f64> = first.q.iter().take(dof).copied().collect();
    let truth = opts.sensor.calibration(arm.sensor_to_tcp);
    let spindle = spindle(arm, opts);
    let mut sim = arm.sim(&q_start, 1.0, (opts.dt, opts.substeps), spindle.as_ref())?;
    let mut comp = compensator(mode, offline.rate_hz, opts, model, calibration)?;
    let pilot = offline.pilot_wrenches(opts.estimate_lead);
    let mut stock = RunStock::new(setup)?;
    let mut noise = Noise::new(opts.seed);
    let dt = opts.dt;
    let cycle = 1.0 / offline.rate_hz;
    let sub = ((cycle / dt).round() as usize).max(1);
    let mut ik = arm.ik_data(&q_start);
    let mut queue: std::collections::VecDeque<Vec<f64>> =
        std::iter::repeat_n(vec![0.0; dof], opts.delay_cycles).collect();
    let mut lag = vec![0.0; dof];
    let alpha = dt / (opts.servo_tau + dt);
    let mut dq_target = vec![0.0; dof];
    let mut q_cmd = q_start.clone();
    let mut force_w = Vector3::zeros();
    let mut engaged: Option<(f64, [f64; 2], usize)> = None;
    let mut samples = Vec::with_capacity(offline.samples.len());
    let mut cutting = Vec::with_capacity(offline.samples.len());
    let joints = |k: usize, s: &job::JobSample| run_joints(mode, feedforward.get(k), dof, s);
    for (k, s) in offline.samples.iter().enumerate() {
        let (kn, next) = offline.samples.get(k + 1).map_or((k, s), |n| (k + 1, n));
        let (q_a, q_b) = (joints(k, s), joints(kn, next));
        let p_nom = s.path.position;
        let dir_base = to_base.rotation * s.path.direction;
        let v_nom = dir_base * s.path.speed;
        // The sensor is read at the start of the cycle.
        let tcp = sim.tcp_pose().translation.vector;
        let tip = (to_work * Point3::from(tcp)).coords;
        let f_base = to_base.rotation * force_w;
        let sensor = arm.sensor_pose(&sim);
        let reading = opts
            .sensor
            .reading(&truth, &sensor, &tcp, &f_base, &mut noise, 1.0);
        samples.push(program_sample(s, &tip, &force_w, engaged));
        cutting.push(s.path.feed_move && !s.contact.arcs().is_empty());
        if let Some(compensator) = comp.as_mut() {
            let est = pilot.get(k).copied().unwrap_or_else(Vector6::zeros);
            let cx = CycleInputs {
                joint_output: mode == ProgramMode::AxisSpecific,
                q_cmd: &q_cmd,
                reading: &reading,
                estimate: &est,
                v_nom: &v_nom,
                nominal: (to_base, p_nom, setup.tool_orientation),
                q_a: &q_a,
            };
            correct(compensator, &cx, (arm, &mut ik), &mut dq_target)?;
        }
        queue.push_back(dq_target.clone());
        let dq_servo = queue.pop_front().unwrap_or_else(|| vec![0.0; dof]);
        let fz = job::feed_per_tooth(setup, &s.path);
        for j in 0..sub {
            let u = j as f64 / sub as f64;
            let qd = servo_command(
                &mut q_cmd,
                &mut lag,
                &dq_servo,
                (&q_a, &q_b),
                alpha,
                (u, dt),
            );
            // The force where the tool is: the engagement on this run's stock at the
            // simulated tip, then the cut to it.
            let tip = (to_work * Point3::from(sim.tcp_pose().translation.vector)).coords;
            let w;
            (force_w, w, engaged) = stock.step(&tip, &s.path, fz)?;
            let w_base = rotate(&to_base.rotation, &w);
            sim.step_servo(&q_cmd, &qd, &vec![0.0; dof], Some(&w_base));
        }
    }
    let cuts = cuts(offline, stock.cutter.radius());
    let part_error = offline.surface_error(&stock.part);
    Ok(ProgramRun {
        mode,
        metrics: metrics(&samples, &cuts, &cutting),
        part: stock.part,
        part_error,
        samples,
    })
}

/// The joints \[rad\] a run of `mode` follows at sample `s`: the pass's rigid joints, its
/// compensated ones (offline), or the rigid ones plus the inertial feed-forward `ff`
/// (combined).
fn run_joints(
    mode: ProgramMode,
    ff: Option<&[f64; deflect_core::vjm::MAX_DOF]>,
    dof: usize,
    s: &job::JobSample,
) -> Vec<f64> {
    let q = if mode == ProgramMode::Offline {
        &s.q_commanded
    } else {
        &s.q
    };
    match (mode, ff) {
        (ProgramMode::Combined, Some(ff)) => {
            q.iter().zip(ff).take(dof).map(|(a, b)| a + b).collect()
        }
        _ => q.iter().take(dof).copied().collect(),
    }
}

/// The compensator of `mode` at the pass's rate `rate_hz` (none uncompensated or offline),
/// with the identified `model` and the sensor's `calibration`.
fn compensator(
    mode: ProgramMode,
    rate_hz: f64,
    opts: &MillingOptions,
    model: &Model,
    calibration: &SensorCalibration,
) -> Result<Option<(compensation::Model, compensation::Data)>, SimError> {
    Ok(match mode {
        ProgramMode::Uncompensated | ProgramMode::Offline => None,
        ProgramMode::Cartesian
        | ProgramMode::Hybrid
        | ProgramMode::AxisSpecific
        | ProgramMode::Combined => {
            let mut cfg = CompensatorConfig::paper(1.0 / rate_hz, *calibration);
            cfg.pilot = (mode != ProgramMode::Cartesian).then_some(opts.pilot);
            if mode == ProgramMode::AxisSpecific {
                cfg.output = CorrectionOutput::Joint;
            }
            let c = compensation::Model::new(model.clone(), cfg)
                .map_err(|e| SimError::new(format!("compensator: {e}")))?;
            let d = compensation::Data::new(&c);
            Some((c, d))
        }
    })
}

/// The cycle's log entry: where the tool is (`tip`, workpiece frame \[m\]) against the
/// program, the force on it \[N\] and its engagement.
fn program_sample(
    s: &job::JobSample,
    tip: &Vector3<f64>,
    force_w: &Vector3<f64>,
    engaged: Option<(f64, [f64; 2], usize)>,
) -> ProgramSample {
    let p_nom = s.path.position;
    let d = tip - p_nom;
    let across = d - s.path.direction * d.dot(&s.path.direction);
    ProgramSample {
        t: s.path.time,
        line: s.path.line,
        nominal: p_nom.into(),
        actual: (*tip).into(),
        force: (*force_w).into(),
        depth: engaged.map_or(0.0, |e| e.0),
        angles: engaged.map_or([0.0; 2], |e| e.1),
        arcs: engaged.map_or(0, |e| e.2),
        error_mm: across.norm() * 1e3,
    }
}

/// The spindle the simulated arm carries ([`MillingOptions::spindle_mass`]): a point mass
/// halfway between the TCP and the sensor (TCP frame), none when massless.
pub fn spindle(
    arm: &MillingArm,
    opts: &MillingOptions,
) -> Option<deflect_core::dalembert::serial::Payload> {
    (opts.spindle_mass > 0.0).then(|| {
        let sensor = arm.sensor_to_tcp.inverse().translation.vector;
        deflect_core::dalembert::serial::Payload::point(opts.spindle_mass, sensor * 0.5)
    })
}

/// The combined run's inertial feed-forward per sample of `offline` (see the module docs):
/// the compensated joints of the pass of `job` with the inertia of `opts` less `offline`'s.
/// Empty when the inertia counts nothing; with it the loaded pass's figures per line.
#[allow(clippy::type_complexity)]
fn feedforward(
    arm: &MillingArm,
    opts: &MillingOptions,
    job: &Job,
    program: &deflect_core::machining::Program,
    seed: &[f64],
    offline: &Report,
) -> Result<
    (
        Vec<[f64; deflect_core::vjm::MAX_DOF]>,
        Vec<job::LineSummary>,
    ),
    SimError,
> {
    let payload = spindle(arm, opts).unwrap_or(deflect_core::dalembert::serial::Payload::point(
        0.0,
        Vector3::zeros(),
    ));
    let inertia = job::Inertia {
        payload,
        links: opts.link_inertia,
    };
    let with = job
        .clone()
        .with_inertia(inertia)
        .map_err(|e| SimError::new(format!("spindle inertia: {e}")))?;
    if with.inertia().is_none() {
        return Ok((Vec::new(), Vec::new()));
    }
    let loaded = job::run(&with, program, seed)
        .map_err(|e| SimError::new(format!("offline pass with inertia: {e}")))?;
    let ff = loaded
        .samples
        .iter()
        .zip(&offline.samples)
        .map(|(a, b)| {
            let mut d = [0.0; deflect_core::vjm::MAX_DOF];
            for ((d, x), y) in d.iter_mut().zip(&a.q_commanded).zip(&b.q_commanded) {
                *d = x - y;
            }
            d
        })
        .collect();
    Ok((ff, loaded.summary.lines()))
}

/// The KR 300's workpiece placement for the program scenario: a table in front of it, the
/// workpiece frame's origin at (2.52, 0.07, 0.92) m, z up, x towards the robot; the tool points
/// down from the joints [`PROGRAM_SEED`].
pub fn kr300_placement() -> Isometry3<f64> {
    Isometry3::new(
        Vector3::new(2.52, 0.07, 0.92),
        Vector3::new(0.0, 0.0, std::f64::consts::PI),
    )
}

/// The program scenarios' options: `opts` in its `program_substeps` substeps.
pub(super) fn scenario_options(opts: &MillingOptions) -> MillingOptions {
    MillingOptions {
        substeps: opts.program_substeps,
        ..opts.clone()
    }
}

/// The program runs' options: `opts` with the physics step at most its `program_dt`, a whole
/// fraction of the control cycle.
pub(super) fn run_options(opts: &MillingOptions) -> MillingOptions {
    let steps = (opts.cycle / opts.program_dt - 1e-9).ceil().max(1.0);
    MillingOptions {
        dt: opts.cycle / steps,
        ..opts.clone()
    }
}

/// Joints near the start of a program on [`kr300_placement`]: the tool down over the table.
pub const PROGRAM_SEED: [f64; 6] = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];

/// Everything the program scenario produced.
#[derive(Debug, Clone)]
pub struct ProgramResult {
    /// The arm's name.
    pub robot: String,
    /// The offline pass (identified model, nominal forces).
    pub offline: Report,
    /// The offline pass's cuts, whose first and last tool radius of travel are the entry
    /// and exit phases of the metrics.
    pub cuts: Vec<Cut>,
    /// One run per mode, in [`ProgramMode::ALL`] order.
    pub runs: Vec<ProgramRun>,
    /// The offline pass with the combined run's inertia, per program line: the process and
    /// inertial parts of the deflection and the peak acceleration (empty when the inertia
    /// counts nothing).
    pub lines: Vec<job::LineSummary>,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
}

/// The scenario: identification of stiffnesses and sensor (as the groove scenario), the offline
/// pass of `program` with the identified model (`setup`'s path sampled at the control cycle),
/// then one rapier run per mode on worker threads (results do not depend on their number).
pub fn milling_program(
    opts: &MillingOptions,
    arm: &MillingArm,
    program: &deflect_core::machining::Program,
    setup: &job::Setup,
    seed: &[f64],
) -> Result<ProgramResult, SimError> {
    let start = std::time::Instant::now();
    let opts = &scenario_options(opts);
    let stiffness = super::identification::identify_stiffness(arm, opts, opts.jobs)?;
    let identified: Vec<(usize, usize, f64)> = stiffness
        .iter()
        .map(|e| (e.spring, e.axis, e.k_frames))
        .collect();
    let model = arm.model_with(&identified)?;
    let (calibration, _) = super::identification::identify_sensor_calibration(arm, opts)?;
    let mut setup = *setup;
    setup.path.rate_hz = 1.0 / opts.cycle;
    let job = Job::new(model.clone(), &arm.spec.robot.joint_limits, setup)
        .map_err(|e| SimError::new(format!("machining job: {e}")))?;
    let offline =
        job::run(&job, program, seed).map_err(|e| SimError::new(format!("offline pass: {e}")))?;
    let (feedforward, lines) = feedforward(arm, opts, &job, program, seed, &offline)?;
    let run_opts = run_options(opts);
    let inputs = RunInputs {
        job: &job,
        offline: &offline,
        feedforward: &feedforward,
        model: &model,
        calibration: &calibration,
    };
    let runs = crate::workers::parallel_map(&ProgramMode::ALL, opts.jobs, |&mode| {
        run_program(arm, &run_opts, &inputs, mode)
    })?
    .into_iter()
    .collect::<Result<Vec<_>, _>>()?;
    Ok(ProgramResult {
        robot: arm.name.clone(),
        cuts: cuts(&offline, setup.tool.diameter / 2.0),
        offline,
        runs,
        lines,
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}
