//! The milling runs: settings and nominal motion ([`MillingOptions`]), the process force and
//! its offline estimate, one run of the groove per compensation [`Mode`] with the online
//! compensation of Hähn and Weigold (sec. 2.2-2.4) in the loop, its path-error [`Metrics`],
//! and the whole scenario ([`milling`]).

use deflect_core::compensation::{self, CompensatorConfig, SensorCalibration};
use deflect_core::vjm::{Model, Vector6};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::Serialize;

use super::arm::MillingArm;
use super::identification::{
    JointEstimate, SensorEstimate, identify_sensor_calibration, identify_stiffness,
};
use super::options::MillingOptions;
use crate::SimError;
use crate::noise::Noise;

/// Which compensation a run uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Mode {
    /// No compensation.
    Uncompensated,
    /// Online compensation with measured forces (pilot off).
    Cartesian,
    /// Online compensation with pilot control from the offline estimate.
    Pilot,
    /// As `Cartesian`, but with an empty sensor calibration (offsets and tool weight not
    /// removed): shows why the sensor identification matters.
    Uncalibrated,
}

impl Mode {
    /// Short name for topics and files.
    pub fn label(self) -> &'static str {
        match self {
            Self::Uncompensated => "uncompensated",
            Self::Cartesian => "cartesian",
            Self::Pilot => "pilot",
            Self::Uncalibrated => "uncalibrated",
        }
    }
}

/// One control cycle of a run.
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    /// Time \[s\].
    pub t: f64,
    /// Nominal tool point \[m\].
    pub nominal: [f64; 3],
    /// Simulated tool point \[m\].
    pub actual: [f64; 3],
    /// Commanded tool point (nominal + correction) \[m\].
    pub commanded: [f64; 3],
    /// Joint command \[rad\].
    pub q_motor: Vec<f64>,
    /// True process force \[N\].
    pub force_true: [f64; 3],
    /// Raw sensor reading (sensor frame) \[N, N m\].
    pub force_measured: [f64; 6],
    /// Filtered, compensated TCP wrench (base frame) \[N, N m\].
    pub force_filtered: [f64; 6],
    /// Wrench fed to the model (after pilot control) \[N, N m\].
    pub force_used: [f64; 6],
    /// Correction `[dp; dr]` \[m, rad\].
    pub correction: [f64; 6],
    /// Pilot weight of the estimate.
    pub pilot_weight: f64,
    /// Distance of the tool point from the nominal line (across the feed) \[mm\].
    pub error_mm: f64,
}

/// Path-error metrics of a run \[mm\].
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Metrics {
    /// Max deviation from cutter entry (start of the force rise) to 0.1 s after the force
    /// has fallen at exit.
    pub max_mm: f64,
    /// RMS deviation over the same window.
    pub rms_mm: f64,
    /// Max deviation from 0.1 s after the force has risen to exit (steady cutting).
    pub steady_max_mm: f64,
    /// Max deviation around entry (from 0.1 s before to 0.1 s after the force has risen).
    pub entry_max_mm: f64,
    /// Max deviation around exit (from 0.1 s before to 0.1 s after the force has fallen).
    pub exit_max_mm: f64,
}

/// A finished run.
#[derive(Debug, Clone, Serialize)]
pub struct Run {
    /// The compensation used.
    pub mode: Mode,
    /// Errors.
    pub metrics: Metrics,
    /// Per-cycle log.
    pub samples: Vec<Sample>,
}

/// Everything the scenario produced.
#[derive(Debug, Clone, Serialize)]
pub struct MillingResult {
    /// Settings.
    pub options: MillingOptions,
    /// Stiffness identification per joint.
    pub stiffness: Vec<JointEstimate>,
    /// Sensor identification.
    pub sensor: SensorEstimate,
    /// The runs: uncompensated, Cartesian, pilot, uncalibrated.
    pub runs: Vec<Run>,
    /// Simulated time of the runs and the static tests \[s\].
    pub sim_seconds: f64,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
}

fn metrics(opts: &MillingOptions, samples: &[Sample]) -> Metrics {
    let (te, tx) = (opts.t_entry(), opts.t_exit());
    let max_in = |a: f64, b: f64| {
        samples
            .iter()
            .filter(|s| s.t >= a && s.t <= b)
            .map(|s| s.error_mm)
            .fold(0.0, f64::max)
    };
    let win: Vec<f64> = samples
        .iter()
        .filter(|s| s.t >= te && s.t <= tx + opts.force_rise + 0.1)
        .map(|s| s.error_mm)
        .collect();
    let rms = (win.iter().map(|e| e * e).sum::<f64>() / win.len().max(1) as f64).sqrt();
    Metrics {
        max_mm: max_in(te, tx + opts.force_rise + 0.1),
        rms_mm: rms,
        steady_max_mm: max_in(te + opts.force_rise + 0.1, tx),
        entry_max_mm: max_in(te - 0.1, te + opts.force_rise + 0.1),
        exit_max_mm: max_in(tx - 0.1, tx + opts.force_rise + 0.1),
    }
}

/// The compensator of `mode` (none uncompensated), with the identified `model` and the
/// sensor's `calibration` (the default one for [`Mode::Uncalibrated`]).
fn compensator(
    mode: Mode,
    opts: &MillingOptions,
    model: &Model,
    calibration: &SensorCalibration,
) -> Result<Option<(compensation::Model, compensation::Data)>, SimError> {
    Ok(match mode {
        Mode::Uncompensated => None,
        Mode::Cartesian | Mode::Pilot | Mode::Uncalibrated => {
            let cal = if mode == Mode::Uncalibrated {
                SensorCalibration {
                    sensor_to_tcp: calibration.sensor_to_tcp,
                    ..SensorCalibration::default()
                }
            } else {
                *calibration
            };
            let mut cfg = CompensatorConfig::paper(opts.cycle, cal);
            cfg.pilot = (mode == Mode::Pilot).then_some(opts.pilot);
            let comp = compensation::Model::new(model.clone(), cfg)
                .map_err(|e| SimError::new(format!("compensator: {e}")))?;
            let data = compensation::Data::new(&comp);
            Some((comp, data))
        }
    })
}

/// One physics step's joint command: the nominal joints `qn` plus the servo's offset lagging
/// behind the correction `dq_servo` \[rad\]; its rate \[rad/s\] over `dt` \[s\].
fn servo_command(
    q_cmd: &mut [f64],
    lagged: &mut [f64],
    (dq_servo, qn): (&[f64], &[f64]),
    alpha: f64,
    dt: f64,
) -> Vec<f64> {
    let q_prev = q_cmd.to_vec();
    for (((l, m), d), n) in lagged
        .iter_mut()
        .zip(q_cmd.iter_mut())
        .zip(dq_servo)
        .zip(qn)
    {
        *l += alpha * (d - *l);
        *m = n + *l;
    }
    // Velocity feed-forward from the command's backward difference; the feed is slow
    // and the corrections smooth, so no acceleration feed-forward.
    q_cmd
        .iter()
        .zip(&q_prev)
        .map(|(a, b)| (a - b) / dt)
        .collect()
}

/// One run of the groove with `mode` on `arm`, the compensator using `model` (identified
/// stiffnesses) and `calibration` (identified sensor).
pub fn run(
    arm: &MillingArm,
    opts: &MillingOptions,
    mode: Mode,
    model: &Model,
    calibration: &SensorCalibration,
) -> Result<Run, SimError> {
    let truth = opts.sensor.calibration(arm.sensor_to_tcp);
    let start_pose = arm.forward(&opts.q0)?;
    let start = start_pose.translation.vector;
    let pose_at =
        |p: &Vector3<f64>| Isometry3::from_parts(Translation3::from(*p), start_pose.rotation);
    let mut sim = arm.sim(&opts.q0, 1.0, (opts.dt, opts.substeps), None)?;
    let mut comp = compensator(mode, opts, model, calibration)?;
    let mut noise = Noise::new(opts.seed);
    let dt = opts.dt;
    let dof = arm.dof();
    let sub = ((opts.cycle / dt).round() as usize).max(1);
    let cycles = (opts.t_end() / (sub as f64 * dt)).ceil() as usize;
    // The nominal joints per physics step and the corrected target per cycle, each by the
    // rigid pose IK warm-started from its last solution.
    let (mut ik_nominal, mut ik_target) = (arm.ik_data(&opts.q0), arm.ik_data(&opts.q0));
    // Corrections (joint offsets) in flight to the servos, and the servo's lagged offset.
    let mut queue: std::collections::VecDeque<Vec<f64>> =
        std::iter::repeat_n(vec![0.0; dof], opts.delay_cycles).collect();
    let mut lagged = vec![0.0; dof];
    let alpha = dt / (opts.servo_tau + dt);
    let mut dq_target = vec![0.0; dof];
    let mut samples = Vec::with_capacity(cycles);
    let mut q_cmd = opts.q0.clone();
    let mut step_index = 0usize;
    for c in 0..cycles {
        let t = c as f64 * sub as f64 * dt;
        let (p_nom, v_nom) = opts.nominal(&start, t);
        let q_nom = arm.ik(&mut ik_nominal, &pose_at(&p_nom))?;
        // The sensor is read at the start of the cycle.
        let f_true = opts.process_force(t);
        let sensor = arm.sensor_pose(&sim);
        let tcp = sim.tcp_pose().translation.vector;
        let reading = opts
            .sensor
            .reading(&truth, &sensor, &tcp, &f_true, &mut noise, 1.0);
        let mut sample = Sample {
            t,
            nominal: p_nom.into(),
            actual: tcp.into(),
            commanded: p_nom.into(),
            q_motor: q_cmd.clone(),
            force_true: f_true.into(),
            force_measured: reading.into(),
            force_filtered: [0.0; 6],
            force_used: [0.0; 6],
            correction: [0.0; 6],
            pilot_weight: 0.0,
            error_mm: ((tcp.y - p_nom.y).powi(2) + (tcp.z - p_nom.z).powi(2)).sqrt() * 1e3,
        };
        if let Some((comp, data)) = comp.as_mut() {
            let f_est = opts.estimated_force(t);
            let est = Vector6::new(f_est.x, f_est.y, f_est.z, 0.0, 0.0, 0.0);
            let out = compensation::step(comp, data, &q_cmd, &reading, Some(&est), &v_nom)
                .map_err(|e| SimError::new(format!("compensator step: {e}")))?;
            // The commanded pose: the nominal one moved by the correction [dp; dr].
            let dp: Vector3<f64> = out.correction.fixed_rows::<3>(0).into_owned();
            let dr: Vector3<f64> = out.correction.fixed_rows::<3>(3).into_owned();
            let target = Isometry3::from_parts(
                Translation3::from(p_nom + dp),
                UnitQuaternion::from_scaled_axis(dr) * start_pose.rotation,
            );
            let q_target = arm.ik(&mut ik_target, &target)?;
            for ((d, a), b) in dq_target.iter_mut().zip(&q_target).zip(&q_nom) {
                *d = a - b;
            }
            sample.commanded = (p_nom + dp).into();
            sample.force_filtered = out.measured_wrench.into();
            sample.force_used = out.wrench.into();
            sample.correction = out.correction.into();
            sample.pilot_weight = out.pilot_weight;
        }
        samples.push(sample);
        queue.push_back(dq_target.clone());
        let dq_servo = queue.pop_front().unwrap_or_else(|| vec![0.0; dof]);
        for _ in 0..sub {
            let ts = step_index as f64 * dt;
            let (p, _) = opts.nominal(&start, ts);
            let qn = arm.ik(&mut ik_nominal, &pose_at(&p))?;
            let qd = servo_command(&mut q_cmd, &mut lagged, (&dq_servo, &qn), alpha, dt);
            let f = opts.process_force(ts);
            let w = Vector6::new(f.x, f.y, f.z, 0.0, 0.0, 0.0);
            sim.step_servo(&q_cmd, &qd, &vec![0.0; dof], Some(&w));
            step_index += 1;
        }
    }
    Ok(Run {
        mode,
        metrics: metrics(opts, &samples),
        samples,
    })
}

/// The whole scenario: identification of stiffnesses and sensor, then the three runs with the
/// identified values (and a fourth, Cartesian compensation without sensor calibration).
pub fn milling(opts: &MillingOptions) -> Result<MillingResult, SimError> {
    let start = std::time::Instant::now();
    let arm = MillingArm::kr300()?;
    let stiffness = identify_stiffness(&arm, opts, opts.jobs)?;
    // The compensator's model: the frame-pair estimates (the file's value where an axis was
    // not identifiable from the loads).
    let identified: Vec<(usize, usize, f64)> = stiffness
        .iter()
        .map(|e| (e.spring, e.axis, e.k_frames))
        .collect();
    let model = arm.model_with(&identified)?;
    let (calibration, sensor) = identify_sensor_calibration(&arm, opts)?;
    let modes = [
        Mode::Uncompensated,
        Mode::Cartesian,
        Mode::Pilot,
        Mode::Uncalibrated,
    ];
    let runs = crate::workers::parallel_map(&modes, opts.jobs, |&mode| {
        run(&arm, opts, mode, &model, &calibration)
    })?
    .into_iter()
    .collect::<Result<Vec<_>, _>>()?;
    Ok(MillingResult {
        options: opts.clone(),
        stiffness,
        sensor,
        runs,
        sim_seconds: opts.t_end() * 4.0
            + opts.id_poses.clamp(1, 3) as f64 * 12.0 * (opts.id_hold + 0.03),
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}
