//! One run of the serial testbed and the whole scenario: the static check, the motions'
//! reachability, each path with and without the corrector, the evaluation.

use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::mechanism::{PoseIkOptions, Task};
use deflect_core::motion::PoseState;
use deflect_core::vjm::Deflection;
use deflect_core::vjm::{self, Data, Vector6};
use nalgebra::Isometry3;
use serde::Serialize;

use super::motion::{MotionParams, PathKind};
use crate::SimError;
use crate::urdf_arm::{ArmSpec, FlexSerialArm, ServoParams};

/// Everything a serial testbed run needs besides the arm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SerialOptions {
    /// The robot's label for tables and logs ("KR 300 R2500", a file name).
    pub robot: String,
    /// Start joints \[rad\].
    pub q0: Vec<f64>,
    /// Payload and tool beyond the TCP.
    #[serde(serialize_with = "payload_json")]
    pub payload: Payload,
    /// Size and pace of the motions.
    pub motion: MotionParams,
    /// Servo and structure of the simulated arm.
    pub servo: ServoParams,
    /// Hold after the motion \[s\] (logged, not evaluated).
    pub tail: f64,
    /// Deflection model the corrector inverts.
    #[serde(serialize_with = "deflection_json")]
    pub model: Deflection,
    /// Whether the corrector also cancels the links' own inertial loads (deflect-core's
    /// `serial::Model::with_link_inertia`), from the URDF's inertials; off, only the payload's.
    pub link_inertia: bool,
    /// What the IK controls (the pose; position and tool axis, position and spin, or position
    /// on an arm with fewer than six joints), corrected and uncorrected alike.
    #[serde(serialize_with = "task_json")]
    pub task: Task,
}

fn task_json<S: serde::Serializer>(t: &Task, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(t.name())
}

/// The serial corrector of `spec`'s chain with its joint limits and `task`, carrying
/// `payload`.
fn corrector(spec: &ArmSpec, payload: Payload, task: Task) -> Result<serial::Model, SimError> {
    let model = serial::Model::new(spec.robot.model.clone(), payload)?
        .with_joint_limits(&spec.robot.joint_limits)?;
    let ik = PoseIkOptions {
        task,
        ..*model.ik_options()
    };
    Ok(model.with_ik_options(ik)?)
}

fn payload_json<S: serde::Serializer>(p: &Payload, s: S) -> Result<S::Ok, S::Error> {
    let i = p.inertia;
    serde_json::json!({
        "mass_kg": p.mass,
        "com_m": [p.com.x, p.com.y, p.com.z],
        "inertia_kg_m2": [[i[(0, 0)], i[(0, 1)], i[(0, 2)]], [i[(1, 0)], i[(1, 1)], i[(1, 2)]],
                          [i[(2, 0)], i[(2, 1)], i[(2, 2)]]],
    })
    .serialize(s)
}

fn deflection_json<S: serde::Serializer>(d: &Deflection, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(match d {
        Deflection::Exact => "exact",
        Deflection::Linearized => "linearized",
    })
}

/// One tick of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SerialSample {
    /// Time \[s\].
    pub t: f64,
    /// Whether the motion is running (evaluated), not the hold after it.
    pub active: bool,
    /// Desired TCP position \[m\] and orientation (quaternion w, x, y, z).
    pub desired: [f64; 7],
    /// Actual TCP position \[m\] and orientation (quaternion w, x, y, z).
    pub actual: [f64; 7],
    /// Commanded rigid TCP position \[m\] (what the joints command without load).
    pub commanded: [f64; 3],
    /// Joint command \[rad\].
    pub q_cmd: Vec<f64>,
    /// Link-side joint angles \[rad\].
    pub q_link: Vec<f64>,
    /// Inertial wrench the corrector cancels \[N, N m\] (zero uncorrected).
    pub wrench: [f64; 6],
}

/// What a run scores (over the motion), in mm and mrad.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SerialMetrics {
    /// Largest distance of the TCP from the planned path \[mm\].
    pub path_max_mm: f64,
    /// RMS distance from the planned path \[mm\].
    pub path_rms_mm: f64,
    /// Largest tracking error (actual minus desired position at the same tick) \[mm\].
    pub track_max_mm: f64,
    /// Largest orientation error (angle of actual against desired) \[mrad\].
    pub rot_max_mrad: f64,
    /// RMS orientation error \[mrad\].
    pub rot_rms_mrad: f64,
    /// Largest commanded correction (commanded minus desired position) \[mm\].
    pub correction_max_mm: f64,
}

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SerialRun {
    /// The path.
    pub path: PathKind,
    /// With the D'Alembert corrector.
    pub corrected: bool,
    /// Motion duration \[s\].
    pub duration: f64,
    /// Scores.
    pub metrics: SerialMetrics,
    /// Every tick.
    #[serde(skip)]
    pub samples: Vec<SerialSample>,
}

/// The static check and every run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SerialResult {
    /// Settings.
    pub options: SerialOptions,
    /// Rigid bodies of the simulated arm.
    pub bodies: usize,
    /// Largest relative difference of the rapier arm's static TCP deflection and
    /// deflect-core's `J K^-1 J^T w` over six small wrenches at the start pose.
    pub static_rel_error: f64,
    /// Runs: line and circle, each uncorrected and corrected.
    pub runs: Vec<SerialRun>,
    /// Simulated time of the runs \[s\] (static check excluded).
    pub sim_seconds: f64,
    /// Wall-clock time of the runs \[s\] (static check excluded).
    pub wall_seconds: f64,
}

fn pose7(p: &Isometry3<f64>) -> [f64; 7] {
    let t = p.translation.vector;
    let q = p.rotation;
    [t.x, t.y, t.z, q.w, q.i, q.j, q.k]
}

/// Damping multiplier of the static check (as the milling identification's static tests).
const STATIC_DAMPING: f64 = 30.0;

/// The rapier arm's static TCP deflection against `J K^-1 J^T w` at `q0`: the largest
/// relative difference over forces of 100 N along x, y, z and moments of 20 N m (both times
/// the softest virtual-joint stiffness over 5000 N m/rad on an arm with a softer one, so the
/// springs turn by milliradians, where `J K^-1 J^T` holds), the six loads on up to `jobs`
/// threads.
pub fn static_check(
    spec: &ArmSpec,
    q0: &[f64],
    servo: &ServoParams,
    jobs: usize,
) -> Result<f64, SimError> {
    let model = &spec.robot.model;
    let c = vjm::compliance(model, &mut Data::new(model), q0)?;
    let k_min = spec
        .bodies
        .iter()
        .filter_map(|b| match &b.piece {
            crate::urdf_arm::Piece::Spring { k, .. } => k.iter().copied().reduce(f64::min),
            _ => None,
        })
        .fold(f64::INFINITY, f64::min);
    let scale = (k_min / 5000.0).min(1.0);
    let loads: Vec<usize> = (0..6).collect();
    let errors = crate::workers::parallel_map(&loads, jobs, |&k| {
        let mut w = Vector6::zeros();
        if let Some(x) = w.get_mut(k) {
            *x = scale * if k < 3 { 100.0 } else { 20.0 };
        }
        // Damped 30x to settle within the steps (static readings do not depend on damping):
        // a soft hobby arm rings for seconds at its structural 2 %.
        let mut arm = FlexSerialArm::new(spec, q0, None, servo, STATIC_DAMPING)?;
        let d = arm.static_deflection(&w, 20_000);
        let want = c * w;
        Ok::<f64, SimError>((d - want).norm() / want.norm().max(f64::MIN_POSITIVE))
    })?;
    errors
        .into_iter()
        .try_fold(0.0f64, |worst, e| e.map(|e| worst.max(e)))
}

/// The planned ticks of `path` from the start pose.
pub fn plan(
    path: PathKind,
    start: &Isometry3<f64>,
    params: &MotionParams,
    rate_hz: f64,
) -> Result<Vec<PoseState>, SimError> {
    match path {
        PathKind::Line => super::motion::line(start, params, rate_hz),
        PathKind::Circle => super::motion::circle(start, params, rate_hz),
    }
}

/// Checks that both motions from `opts.q0` plan and that the rigid pose IK follows them
/// within the joint limits, in deflect-core alone (no physics): the error names the path
/// and the tick.
pub fn check_motions(spec: &ArmSpec, opts: &SerialOptions) -> Result<(), SimError> {
    let model = &spec.robot.model;
    let start = vjm::forward(model, &mut Data::new(model), &opts.q0)?;
    let rigid = corrector(
        spec,
        Payload::point(0.0, nalgebra::Vector3::zeros()),
        opts.task,
    )?;
    for path in [PathKind::Line, PathKind::Circle] {
        let states = plan(path, &start, &opts.motion, 1.0 / opts.servo.dt)?;
        let mut data = serial::Data::new(&rigid);
        data.set_seed(&opts.q0);
        for (k, s) in states.iter().enumerate() {
            // Only reachability is checked here: the tick itself is not needed.
            let _reachable = serial::step(&rigid, &mut data, s, None).map_err(|e| {
                SimError::new(format!(
                    "{} at t = {:.3} s (tick {k}): {e}",
                    path.label(),
                    s.t
                ))
            })?;
        }
    }
    Ok(())
}

/// One run of `path`, with or without the corrector.
pub fn run(
    spec: &ArmSpec,
    opts: &SerialOptions,
    path: PathKind,
    corrected: bool,
) -> Result<SerialRun, SimError> {
    let model = &spec.robot.model;
    let start = vjm::forward(model, &mut Data::new(model), &opts.q0)?;
    let dt = opts.servo.dt;
    let states = plan(path, &start, &opts.motion, 1.0 / dt)?;
    let duration = states.last().map_or(0.0, |s| s.t);
    // The corrector; uncorrected = the same solver with no load (rigid pose IK).
    let payload = if corrected {
        opts.payload
    } else {
        Payload::point(0.0, nalgebra::Vector3::zeros())
    };
    let corrector = corrector(spec, payload, opts.task)?
        .with_deflection(opts.model)
        .with_link_inertia(corrected && opts.link_inertia);
    let mut data = serial::Data::new(&corrector);
    data.set_seed(&opts.q0);
    let mut arm = FlexSerialArm::new(spec, &opts.q0, Some(&opts.payload), &opts.servo, 1.0)?;
    let dof = model.dof();
    let n_motion = states.len();
    let n_total = n_motion + (opts.tail / dt).ceil() as usize;
    let mut samples = Vec::with_capacity(n_total);
    let (mut q_prev, mut qd_prev) = (opts.q0.clone(), vec![0.0; dof]);
    let mut last = None;
    for k in 0..n_total {
        let state = match states.get(k) {
            Some(s) => *s,
            None => match states.last() {
                Some(s) => PoseState::at_rest(k as f64 * dt, s.pose),
                None => PoseState::at_rest(0.0, start),
            },
        };
        let tick = match (k < n_motion, last) {
            (false, Some(t)) => t,
            _ => serial::step(&corrector, &mut data, &state, None)
                .map_err(|e| SimError::new(format!("{} tick {k}: {e}", path.label())))?,
        };
        last = Some(tick);
        let q: Vec<f64> = tick.joints.iter().take(dof).copied().collect();
        let qd: Vec<f64> = if k == 0 {
            vec![0.0; dof]
        } else {
            q.iter().zip(&q_prev).map(|(a, b)| (a - b) / dt).collect()
        };
        let qdd: Vec<f64> = if k == 0 {
            vec![0.0; dof]
        } else {
            qd.iter().zip(&qd_prev).map(|(a, b)| (a - b) / dt).collect()
        };
        arm.step_servo(&q, &qd, &qdd, None);
        let actual = arm.tcp_pose();
        let (q_link, _) = arm.joint_state();
        let c = tick.commanded.translation.vector;
        let w = if corrected {
            tick.load
        } else {
            Vector6::zeros()
        };
        samples.push(SerialSample {
            t: k as f64 * dt,
            active: k < n_motion,
            desired: pose7(&state.pose),
            actual: pose7(&actual),
            commanded: [c.x, c.y, c.z],
            q_cmd: q.clone(),
            q_link,
            wrench: [w[0], w[1], w[2], w[3], w[4], w[5]],
        });
        q_prev = q;
        qd_prev = qd;
    }
    let metrics = evaluate(path, &start, &opts.motion, &samples);
    Ok(SerialRun {
        path,
        corrected,
        duration,
        metrics,
        samples,
    })
}

pub(crate) fn pose_of(p: &[f64; 7]) -> Isometry3<f64> {
    Isometry3::from_parts(
        nalgebra::Translation3::new(p[0], p[1], p[2]),
        nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(p[3], p[4], p[5], p[6])),
    )
}

/// The scores of a run's samples (over the motion).
pub fn evaluate(
    path: PathKind,
    start: &Isometry3<f64>,
    params: &MotionParams,
    samples: &[SerialSample],
) -> SerialMetrics {
    let mut m = SerialMetrics::default();
    let (mut sq_p, mut sq_r, mut n) = (0.0, 0.0, 0usize);
    for s in samples.iter().filter(|s| s.active) {
        let (a, d) = (pose_of(&s.actual), pose_of(&s.desired));
        let dist = super::motion::path_distance(path, start, params, &a.translation.vector) * 1e3;
        let track = (a.translation.vector - d.translation.vector).norm() * 1e3;
        let rot = a.rotation.angle_to(&d.rotation) * 1e3;
        let corr = (nalgebra::Vector3::from(s.commanded) - d.translation.vector).norm() * 1e3;
        m.path_max_mm = m.path_max_mm.max(dist);
        m.track_max_mm = m.track_max_mm.max(track);
        m.rot_max_mrad = m.rot_max_mrad.max(rot);
        m.correction_max_mm = m.correction_max_mm.max(corr);
        sq_p += dist * dist;
        sq_r += rot * rot;
        n += 1;
    }
    if n > 0 {
        m.path_rms_mm = (sq_p / n as f64).sqrt();
        m.rot_rms_mrad = (sq_r / n as f64).sqrt();
    }
    m
}

/// The static check and the four runs (line and circle, uncorrected and corrected) on up to
/// `jobs` threads; results do not depend on `jobs`.
pub fn serial(spec: &ArmSpec, opts: &SerialOptions, jobs: usize) -> Result<SerialResult, SimError> {
    let static_rel_error = static_check(spec, &opts.q0, &opts.servo, jobs)?;
    let start = std::time::Instant::now();
    let cases: Vec<(PathKind, bool)> = [PathKind::Line, PathKind::Circle]
        .into_iter()
        .flat_map(|p| [(p, false), (p, true)])
        .collect();
    let runs = crate::workers::parallel_map(&cases, jobs, |&(p, c)| run(spec, opts, p, c))?
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
    let wall_seconds = start.elapsed().as_secs_f64();
    let sim_seconds = runs
        .iter()
        .map(|r| r.samples.len() as f64 * opts.servo.dt)
        .sum();
    let bodies = FlexSerialArm::new(spec, &opts.q0, None, &opts.servo, 1.0)?.body_count();
    Ok(SerialResult {
        options: opts.clone(),
        bodies,
        static_rel_error,
        runs,
        sim_seconds,
        wall_seconds,
    })
}
