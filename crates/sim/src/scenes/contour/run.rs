//! Tracing one object: the tracer of deflect-core ([`deflect_core::contour::step`], Eq. 21)
//! drives the rapier arm through the closed-form IK, the sensor averages the settled contact
//! force with bias and noise, and every contact sample is recovered raw (FK of the motor
//! readings) and compensated (Eq. 10, [`deflect_core::drivetrain::step`]).

use deflect_core::contour::{
    self, TraceDirection, TraceFailure, TracerConfig, TracerState, TracerStats, shape,
};
use deflect_core::drivetrain::{self, cartesian_stiffness_xy};
use nalgebra::{Vector2, Vector6};
use serde::Serialize;

use super::arm::{ArmParams, ArmSim};
use super::objects::{ObjectSpec, Outline, v2};
use super::{DT, err};
use crate::SimError;
use crate::noise::Noise;
use crate::workers::parallel_map;

/// Settings of a trace.
#[derive(Debug, Clone, Serialize)]
pub struct TraceOptions {
    /// The arm.
    pub arm: ArmParams,
    /// Tracer step along the edge `Delta r` \[m\].
    pub step: f64,
    /// Approach step \[m\].
    pub approach_step: f64,
    /// Contact threshold `F_contact_min` \[N\].
    pub contact_force: f64,
    /// Jam force `F_jam_min` \[N\].
    pub jam_force: f64,
    /// Target force \[N\].
    pub target_force: f64,
    /// Motor ramp time per tracer step \[s\].
    pub ramp: f64,
    /// Settling time after the ramp \[s\].
    pub settle: f64,
    /// Sensor averaging window at the end of the settle \[s\].
    pub average: f64,
    /// Sensor noise, standard deviation per sample and axis \[N\].
    pub noise: f64,
    /// Sensor bias \[N\].
    pub bias: [f64; 2],
    /// Seed of the sensor noise.
    pub seed: u64,
    /// Contact penalty stiffness \[N/m\].
    pub k_contact: f64,
    /// Contact penalty damping \[N s/m\].
    pub c_contact: f64,
    /// Tracer steps after which a trace is stopped.
    pub max_steps: usize,
    /// Readings averaged for the sensor bias before the approach.
    pub bias_samples: usize,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            arm: ArmParams::default(),
            step: 1.5e-3,
            approach_step: 1.0e-3,
            contact_force: 1.5,
            jam_force: 30.0,
            target_force: 6.0,
            ramp: 0.020,
            settle: 0.060,
            average: 0.010,
            noise: 0.3,
            bias: [0.7, -0.4],
            seed: 7,
            k_contact: 5.0e5,
            c_contact: 150.0,
            max_steps: 4000,
            bias_samples: 10,
        }
    }
}

/// One tracer step: the settled reading and what the tracer made of it.
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    /// Simulated time at the reading \[s\].
    pub t: f64,
    /// Tracer phase after the reading.
    pub state: &'static str,
    /// Position command the arm held for the reading \[m\].
    pub command: [f64; 2],
    /// True tool point at the reading \[m\].
    pub tool_actual: [f64; 2],
    /// Sensed force, raw (bias and noise included) \[N\].
    pub force_sensed: [f64; 2],
    /// Bias-removed sensed force the tracer used \[N\].
    pub force: [f64; 2],
    /// True mean contact force over the averaging window \[N\].
    pub force_true: [f64; 2],
    /// Motor-side joint readings \[rad\].
    pub q_motor: [f64; 2],
    /// Link-side joint angles (simulation truth) \[rad\].
    pub q_link: [f64; 2],
    /// A contact sample: the shape points below are recorded.
    pub contact: bool,
    /// FK of the motor readings \[m\] (contact samples).
    pub raw: Option<[f64; 2]>,
    /// FK of the Eq. 10 corrected joints \[m\] (contact samples).
    pub compensated: Option<[f64; 2]>,
}

/// RMS and max distance to the true outline \[mm\].
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ShapeErr {
    /// RMS \[mm\].
    pub rms_mm: f64,
    /// Max \[mm\].
    pub max_mm: f64,
    /// Points.
    pub count: usize,
}

/// Result of tracing one object.
#[derive(Debug, Clone, Serialize)]
pub struct ContourRun {
    /// Object name.
    pub name: String,
    /// The object.
    pub outline: Outline,
    /// Final tracer state ("done" on success).
    pub state: &'static str,
    /// Tracer steps (readings), including init and approach.
    pub tracer_steps: usize,
    /// Contact samples recorded.
    pub contacts: usize,
    /// Edge directions from Eq. 21 / normal to the force.
    pub eq21_steps: usize,
    /// Edge directions normal to the force.
    pub normal_steps: usize,
    /// Readings out of contact after the first contact (each one a bisected recovery move).
    pub contact_losses: usize,
    /// Longest run of consecutive readings out of contact.
    pub longest_loss: usize,
    /// Readings at or above the jam force.
    pub jams: usize,
    /// Moves shortened by the jam guard.
    pub shortened: usize,
    /// Largest settled true contact force \[N\].
    pub max_force: f64,
    /// Largest contact force of any physics step (transients included) \[N\].
    pub peak_force: f64,
    /// Path length of the tracer's tool estimates \[m\] and the true perimeter \[m\].
    pub path_length: f64,
    /// True perimeter \[m\].
    pub perimeter: f64,
    /// Shape error of the raw recovered contour.
    pub raw: ShapeErr,
    /// Shape error of the compensated (Eq. 10) contour.
    pub compensated: ShapeErr,
    /// Distance of the true tool points (contact samples) to the outline: the floor set by
    /// the penalty contact's penetration.
    pub actual: ShapeErr,
    /// Simulated time \[s\].
    pub sim_time: f64,
    /// Physics steps.
    pub physics_steps: usize,
    /// Wall time \[s\].
    pub wall: f64,
    /// Every tracer step.
    pub samples: Vec<Sample>,
}

fn shape_err<'a>(outline: &Outline, pts: impl IntoIterator<Item = &'a Vector2<f64>>) -> ShapeErr {
    let e = shape::shape_error(pts, |p| outline.distance(p));
    ShapeErr {
        rms_mm: e.rms * 1e3,
        max_mm: e.max * 1e3,
        count: e.count,
    }
}

fn arr(v: &Vector2<f64>) -> [f64; 2] {
    [v.x, v.y]
}

/// Traces `object` counter-clockwise with deflect-core's tracer ([`contour::step`]) and
/// recovers its shape.
pub fn trace(object: &ObjectSpec, opts: &TraceOptions) -> Result<ContourRun, SimError> {
    let wall = std::time::Instant::now();
    let arm = &opts.arm;
    let drive = arm.drive_train()?;
    let mut data = drivetrain::Data::new(&drive);
    let cfg = tracer_config(opts);
    let start = v2(&object.start);
    let mut q_cmd = arm.ik(&start);
    let k0 = cartesian_stiffness_xy(&drive, &mut data, &q_cmd).map_err(err)?;
    let tracer = contour::Model::new(cfg, &k0).map_err(err)?;
    let mut tracer_data = contour::Data::new(&tracer);
    let mut sim = ArmSim::new(arm, &q_cmd, opts.k_contact, opts.c_contact)?;
    let mut noise = Noise::new(opts.seed ^ 0x5EED_C0DE);
    let (objects, settle) = ([&object.outline], Settle::new(opts));
    let mut cmd = start;
    let mut q_prev = q_cmd;
    let mut samples = Vec::new();
    let (mut raw, mut comp, mut actual) = (Vec::new(), Vec::new(), Vec::new());
    let mut max_force = 0.0f64;
    let mut t = 0.0;
    let mut steps = 0;
    let state = loop {
        steps += 1;
        // Ramp the motors to the command, hold and settle.
        let (f_true, f_sensed) = move_and_settle(
            &mut sim,
            &mut noise,
            (q_prev, q_cmd),
            &objects,
            &settle,
            &mut t,
        );
        max_force = max_force.max(f_true.norm());
        let (q_link, _) = sim.link_state();
        let tool_actual = arm.fk(&q_link);
        // The motor readings are exact (the servo holds the command at rest).
        let q_motor = q_cmd;
        let k = cartesian_stiffness_xy(&drive, &mut data, &q_motor)
            .map_err(|e| err(format!("{e} at t {t} q {q_motor:?} cmd {cmd:?}")))?;
        tracer_data.set_stiffness(&k).map_err(err)?;
        let out = contour::step(&tracer, &mut tracer_data, &cmd, &f_sensed).map_err(err)?;
        let mut sample = Sample {
            t,
            state: out.state.name(),
            command: arr(&cmd),
            tool_actual: arr(&tool_actual),
            force_sensed: arr(&f_sensed),
            force: arr(&out.force),
            force_true: arr(&f_true),
            q_motor,
            q_link,
            contact: out.contact,
            raw: None,
            compensated: None,
        };
        if out.contact {
            let (p_raw, p_comp) = recover(arm, &drive, &mut data, &q_motor, &out.force)?;
            sample.raw = Some(arr(&p_raw));
            sample.compensated = Some(arr(&p_comp));
            raw.push(p_raw);
            comp.push(p_comp);
            actual.push(tool_actual);
        }
        samples.push(sample);
        if out.state.is_finished() {
            break out.state;
        }
        if steps >= opts.max_steps + 200 {
            break TracerState::Failed(TraceFailure::StepLimit);
        }
        cmd = out.command;
        q_prev = q_cmd;
        q_cmd = arm.ik(&cmd);
    };
    let stats: TracerStats = *tracer_data.stats();
    Ok(ContourRun {
        name: object.name.clone(),
        outline: object.outline.clone(),
        state: state.name(),
        tracer_steps: steps,
        contacts: stats.contacts,
        eq21_steps: stats.eq21_steps,
        normal_steps: stats.normal_steps,
        contact_losses: stats.bisections,
        longest_loss: stats.longest_loss,
        jams: stats.jams,
        shortened: stats.shortened,
        max_force,
        peak_force: sim.peak_force,
        path_length: stats.path_length,
        perimeter: object.outline.perimeter(),
        raw: shape_err(&object.outline, &raw),
        compensated: shape_err(&object.outline, &comp),
        actual: shape_err(&object.outline, &actual),
        sim_time: t,
        physics_steps: sim.physics_steps,
        wall: wall.elapsed().as_secs_f64(),
        samples,
    })
}

/// The tracer's settings from the trace's.
fn tracer_config(opts: &TraceOptions) -> TracerConfig {
    let mut cfg = TracerConfig::new(opts.step, opts.contact_force, opts.jam_force);
    cfg.target_force = opts.target_force;
    cfg.approach_step = opts.approach_step;
    cfg.direction = TraceDirection::CounterClockwise;
    cfg.max_steps = opts.max_steps;
    cfg.bias_samples = opts.bias_samples.max(1);
    cfg
}

/// How a command is driven: ramp, settle and averaging ticks, the sensor's bias \[N\] and
/// noise \[N\].
struct Settle {
    n_ramp: usize,
    n_settle: usize,
    n_avg: usize,
    bias: Vector2<f64>,
    noise: f64,
}

impl Settle {
    /// The ticks of the trace's ramp, settle and averaging times \[s\], and its sensor.
    fn new(opts: &TraceOptions) -> Self {
        let bias = v2(&opts.bias);
        let n_ramp = ((opts.ramp / DT).round() as usize).max(1);
        let n_settle = (opts.settle / DT).round() as usize;
        let n_avg = ((opts.average / DT).round() as usize).clamp(1, n_ramp + n_settle);
        Self {
            n_ramp,
            n_settle,
            n_avg,
            bias,
            noise: opts.noise,
        }
    }
}

/// Moves the motors from `q_prev` to `q_cmd` \[rad\] on a cosine ramp, then holds and
/// settles (advancing `t` \[s\]); the true and sensed contact forces \[N\] averaged over the
/// last ticks.
fn move_and_settle(
    sim: &mut ArmSim,
    noise: &mut Noise,
    (q_prev, q_cmd): ([f64; 2], [f64; 2]),
    objects: &[&Outline],
    how: &Settle,
    t: &mut f64,
) -> (Vector2<f64>, Vector2<f64>) {
    let (n_ramp, n_avg) = (how.n_ramp, how.n_avg);
    let total = n_ramp + how.n_settle;
    let (mut f_true, mut f_sensed) = (Vector2::zeros(), Vector2::zeros());
    for k in 0..total {
        let (q, w) = if k < n_ramp {
            let s = (k + 1) as f64 / n_ramp as f64;
            let blend = 0.5 * (1.0 - (core::f64::consts::PI * s).cos());
            let rate = 0.5 * core::f64::consts::PI * (core::f64::consts::PI * s).sin()
                / (n_ramp as f64 * DT);
            (
                [
                    q_prev[0] + (q_cmd[0] - q_prev[0]) * blend,
                    q_prev[1] + (q_cmd[1] - q_prev[1]) * blend,
                ],
                [(q_cmd[0] - q_prev[0]) * rate, (q_cmd[1] - q_prev[1]) * rate],
            )
        } else {
            (q_cmd, [0.0; 2])
        };
        let f = sim.step(&q, &w, objects);
        *t += DT;
        if k + n_avg >= total {
            f_true += f;
            f_sensed += f + how.bias + Vector2::new(noise.gauss(), noise.gauss()) * how.noise;
        }
    }
    f_true /= n_avg as f64;
    f_sensed /= n_avg as f64;
    (f_true, f_sensed)
}

/// The tool point recovered from the motor readings `q_motor` \[rad\] under the contact
/// `force` \[N\]: raw (their forward kinematics) and compensated (Eq. 10).
fn recover(
    arm: &ArmParams,
    drive: &drivetrain::Model,
    data: &mut drivetrain::Data,
    q_motor: &[f64; 2],
    force: &Vector2<f64>,
) -> Result<(Vector2<f64>, Vector2<f64>), SimError> {
    let p_raw = arm.fk(q_motor);
    let w = Vector6::new(force.x, force.y, 0.0, 0.0, 0.0, 0.0);
    let c = drivetrain::step(drive, data, q_motor, &w).map_err(err)?;
    let p_comp = arm.fk(&[c.q[0], c.q[1]]);
    Ok((p_raw, p_comp))
}

/// Traces every object on up to `jobs` worker threads ([`parallel_map`]); results in the
/// order of `objects` whatever `jobs` is.
pub fn trace_all(
    objects: &[ObjectSpec],
    opts: &TraceOptions,
    jobs: usize,
) -> Result<Vec<ContourRun>, SimError> {
    parallel_map(objects, jobs, |o| trace(o, opts))?
        .into_iter()
        .collect()
}
