//! The paper's validation on a five-axis program: the flexible KR 300 in rapier follows the
//! joints of deflect-core's `machining::five_axis` pass (the program's tool axis in every
//! pose), and at every physics step the force on the tool is the cutter's along its edge for
//! the engagement read from the run's own tri-dexel stock *where the simulated tool really is
//! and as it is tilted* (its tip and its axis from the simulated TCP), so the testbed's tool
//! orientation follows the program and the deflection alike. Runs: uncompensated (the rigid
//! joints) and offline compensated (the pass's compensated joints); each run's part is
//! compared with the program's along the surface's normal. The online compensator's
//! projection (normal to the feed, Hähn and Weigold 2020, Eq. 10-11) is 2.5-D and is not run.

use deflect_core::machining::cutting::Coefficients;
use deflect_core::machining::dexel::Dexels;
use deflect_core::machining::five_axis::{self, CutterModel, Options, Report};
use deflect_core::machining::job::{Job, Setup};
use deflect_core::machining::profile::{Band, MAX_BANDS};
use deflect_core::machining::tools::ToolTable;
use deflect_core::vjm::Vector6;
use nalgebra::{Point3, Vector3};

use super::arm::MillingArm;
use super::options::MillingOptions;
use super::program::ProgramMode;
use crate::SimError;

/// A finished run.
#[derive(Debug, Clone)]
pub struct AxisRun {
    /// Uncompensated or offline compensated.
    pub mode: ProgramMode,
    /// Largest distance of the simulated tip from the program while cutting \[m\].
    pub max_tip: f64,
    /// Its root mean square \[m\].
    pub rms_tip: f64,
    /// Largest angle of the simulated tool axis from the program's while cutting \[rad\].
    pub max_axis: f64,
    /// The part this run cut.
    pub part: Dexels,
}

/// Everything the five-axis scenario produced.
#[derive(Debug, Clone)]
pub struct AxisResult {
    /// The arm's name.
    pub robot: String,
    /// The offline pass (identified model, nominal forces).
    pub offline: Report,
    /// One run per mode (uncompensated, offline).
    pub runs: Vec<AxisRun>,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
}

/// The modes a five-axis program runs.
pub const MODES: [ProgramMode; 2] = [ProgramMode::Uncompensated, ProgramMode::Offline];

/// The scenario: the stiffnesses identified (as for 2.5-D programs), the five-axis pass with
/// the identified model, then one rapier run per mode on worker threads.
pub fn milling_five_axis(
    opts: &MillingOptions,
    arm: &MillingArm,
    program: &deflect_core::machining::Program,
    setup: &Setup,
    tools: Option<&ToolTable>,
    options: &Options,
    seed: &[f64],
) -> Result<AxisResult, SimError> {
    let start = std::time::Instant::now();
    let opts = &super::program::scenario_options(opts);
    let stiffness = super::identification::identify_stiffness(arm, opts, opts.jobs)?;
    let identified: Vec<(usize, usize, f64)> = stiffness
        .iter()
        .map(|e| (e.spring, e.axis, e.k_frames))
        .collect();
    let model = arm.model_with(&identified)?;
    let mut setup = *setup;
    setup.path.rate_hz = 1.0 / opts.cycle;
    let mut job = Job::new(model, &arm.spec.robot.joint_limits, setup)
        .map_err(|e| SimError::new(format!("machining job: {e}")))?;
    if let Some(t) = tools {
        job = job.with_tools(t.clone());
    }
    let offline = five_axis::run(&job, program, seed, options)
        .map_err(|e| SimError::new(format!("five-axis pass: {e}")))?;
    let run_opts = super::program::run_options(opts);
    let runs = crate::workers::parallel_map(&MODES, opts.jobs, |&mode| {
        run(arm, &run_opts, &job, &offline, mode, options)
    })?
    .into_iter()
    .collect::<Result<Vec<_>, _>>()?;
    Ok(AxisResult {
        robot: arm.name.clone(),
        offline,
        runs,
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The cutter of tool `number` (the table's, else the setup's with `options.shape`).
fn cutter(job: &Job, number: u32, options: &Options) -> Result<CutterModel, SimError> {
    let (tool, shape) = match job.tools().and_then(|t| t.get(number)) {
        Some(spec) => (spec.tool, spec.shape),
        None => (job.setup().tool, options.shape),
    };
    CutterModel::new(&tool, shape, options.length)
        .map_err(|e| SimError::new(format!("T{number}: {e}")))
}

/// A wrench `[f; m]` turned by `r`.
fn rotate(r: &nalgebra::UnitQuaternion<f64>, w: &Vector6) -> Vector6 {
    let f = r * w.fixed_rows::<3>(0).into_owned();
    let m = r * w.fixed_rows::<3>(3).into_owned();
    Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
}

/// One run of the pass's joints (`mode`: the rigid or the compensated ones) in rapier.
fn run(
    arm: &MillingArm,
    opts: &MillingOptions,
    job: &Job,
    offline: &Report,
    mode: ProgramMode,
    options: &Options,
) -> Result<AxisRun, SimError> {
    let setup = job.setup();
    let (to_base, to_work) = (setup.placement, setup.placement.inverse());
    let back = setup.tool_orientation.inverse();
    let dof = arm.dof();
    let joints = |s: &five_axis::Sample| -> Vec<f64> {
        let q = if mode == ProgramMode::Offline {
            &s.q_commanded
        } else {
            &s.q
        };
        q.iter().take(dof).copied().collect()
    };
    let first = offline
        .samples
        .first()
        .ok_or_else(|| SimError::new("five-axis run: the pass has no samples"))?;
    let q_start = joints(first);
    let mut sim = arm.sim(&q_start, 1.0, (opts.dt, opts.substeps), None)?;
    let st = &setup.stock;
    let mut part = Dexels::block(
        Vector3::new(st.min.x, st.min.y, st.top - options.depth),
        Vector3::new(st.max.x, st.max.y, st.top),
        st.cell,
    )
    .map_err(|e| SimError::new(format!("stock: {e}")))?;
    let mut cutters: Vec<(u32, CutterModel)> = Vec::new();
    let mut bands = [Band::new(0.0, 0.0, 0.0); MAX_BANDS];
    let cycle = 1.0 / offline.rate_hz;
    let sub = ((cycle / opts.dt).round() as usize).max(1);
    let mut q_cmd = q_start.clone();
    let mut prev: Option<(Vector3<f64>, Vector3<f64>)> = None;
    let (mut max_tip, mut sum, mut n, mut max_axis) = (0.0f64, 0.0, 0usize, 0.0f64);
    let pose = |sim: &crate::urdf_arm::sim::FlexSerialArm| {
        let at = to_work * sim.tcp_pose();
        let axis = ((at.rotation * back) * Vector3::z()).normalize();
        ((at * Point3::origin()).coords, axis)
    };
    for (k, s) in offline.samples.iter().enumerate() {
        let next = offline.samples.get(k + 1).unwrap_or(s);
        let (q_a, q_b) = (joints(s), joints(next));
        let c = cutter_of(&mut cutters, job, s.path.tool, options)?;
        let (tip, axis) = pose(&sim);
        if s.bands > 0 {
            let e = (tip - s.path.position).norm();
            max_tip = max_tip.max(e);
            sum += e * e;
            n += 1;
            max_axis = max_axis.max(axis.angle(&s.path.axis));
        }
        // The run's stock cut to where its tool is, once per control cycle (the material
        // the engagement reads behind the tool within a cycle lies where the chip is
        // negative: it cuts nothing).
        let (from, from_axis) = prev.unwrap_or((tip, axis));
        let _ = part
            .cut(&c.solid, &from, &from_axis, &tip, &axis)
            .map_err(|e| SimError::new(format!("program line {}: {e}", s.path.line)))?;
        prev = Some((tip, axis));
        let fz = feed_per_tooth(s, setup, &c);
        for j in 0..sub {
            let u = j as f64 / sub as f64;
            let q_prev = q_cmd.clone();
            for ((m, a), b) in q_cmd.iter_mut().zip(&q_a).zip(&q_b) {
                *m = a + (b - a) * u;
            }
            let qd: Vec<f64> = q_cmd
                .iter()
                .zip(&q_prev)
                .map(|(a, b)| (a - b) / opts.dt)
                .collect();
            // The force where the tool is and as it is tilted, on this run's stock.
            let (tip, axis) = pose(&sim);
            let on = (&part, &c, &mut bands);
            let w = process_wrench(on, (&tip, &axis), s, fz, &setup.coefficients, options)?;
            let w_base = rotate(&to_base.rotation, &w);
            sim.step_servo(&q_cmd, &qd, &vec![0.0; dof], Some(&w_base));
        }
    }
    Ok(AxisRun {
        mode,
        max_tip,
        rms_tip: (sum / n.max(1) as f64).sqrt(),
        max_axis,
        part,
    })
}

/// The cutter model of tool `number`, built once and kept in `cutters`.
fn cutter_of(
    cutters: &mut Vec<(u32, CutterModel)>,
    job: &Job,
    number: u32,
    options: &Options,
) -> Result<CutterModel, SimError> {
    Ok(match cutters.iter().find(|(t, _)| *t == number) {
        Some((_, c)) => *c,
        None => {
            let c = cutter(job, number, options)?;
            cutters.push((number, c));
            c
        }
    })
}

/// The sample's feed per tooth \[m\] (the hand spindle where the program's is off; 0 off a
/// feed move or with the spindle stopped).
fn feed_per_tooth(s: &five_axis::Sample, setup: &Setup, c: &CutterModel) -> f64 {
    let spindle = match (s.path.spindle, setup.hand_spindle) {
        (0.0, Some(hand)) => hand,
        (v, _) => v,
    };
    let teeth = spindle.abs() * f64::from(c.tool.flutes);
    if s.path.feed_move && teeth > 0.0 {
        s.path.speed / teeth
    } else {
        0.0
    }
}

/// The process wrench \[N, N m\] (workpiece frame) on cutter `c` at `tip` with `axis` \[m\]
/// in the run's stock `part`, feeding `fz` \[m\] per tooth: zero out of the material.
fn process_wrench(
    (part, c, bands): (&Dexels, &CutterModel, &mut [Band; MAX_BANDS]),
    (tip, axis): (&Vector3<f64>, &Vector3<f64>),
    s: &five_axis::Sample,
    fz: f64,
    coefficients: &Coefficients,
    options: &Options,
) -> Result<Vector6, SimError> {
    let mut w = Vector6::zeros();
    if fz > 0.0
        && let Some(frame) = five_axis::frame(axis, &s.path.direction)
    {
        let nb = part
            .engagement(&c.solid, tip, &frame, options.slices, options.angles, bands)
            .map_err(|e| SimError::new(format!("program line {}: {e}", s.path.line)))?;
        if nb > 0 {
            let engaged = bands.get(..nb).unwrap_or(&[]);
            let dir = &s.path.direction;
            w = five_axis::edge_wrench(coefficients, c, &frame, engaged, axis, dir, fz)
                .map_err(|e| SimError::new(format!("program line {}: {e}", s.path.line)))?
                .1;
        }
    }
    Ok(w)
}
