//! Identification before the milling runs (Hähn and Weigold, sec. 2.5-2.6): the virtual-joint
//! stiffnesses of the KR 300 from static loads on the arm in rapier (frame-pair rotations
//! across each virtual joint, and 6-D TCP deflections, each by least squares), and the flange
//! sensor's offsets, weight and centre of gravity from unloaded readings at several
//! orientations.

use deflect_core::compensation::SensorCalibration;
use deflect_core::identification::{
    FrameMeasurement, StiffnessIdentification, TcpMeasurement, identify_from_frames,
    identify_from_tcp, identify_sensor,
};
use deflect_core::vjm::Vector6;
use nalgebra::Vector3;
use serde::Serialize;

use super::arm::MillingArm;
use super::options::MillingOptions;
use crate::SimError;
use crate::noise::Noise;

/// Identification of one stiffness (one axis of one virtual joint).
#[derive(Debug, Clone, Serialize)]
pub struct JointEstimate {
    /// Virtual joint index (chain order).
    pub spring: usize,
    /// Axis of the spring frame (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// "link_2 y", "spindle z".
    pub label: String,
    /// True stiffness \[N m/rad\] (the stiffness file's).
    pub k_true: f64,
    /// From frame-pair rotations \[N m/rad\] (NaN: not identifiable from these loads).
    pub k_frames: f64,
    /// Its standard error \[N m/rad\].
    pub se_frames: f64,
    /// From 6-D TCP deflections \[N m/rad\] (NaN: not identifiable).
    pub k_tcp: f64,
    /// Its standard error \[N m/rad\].
    pub se_tcp: f64,
}

/// Result of the sensor identification.
#[derive(Debug, Clone, Serialize)]
pub struct SensorEstimate {
    /// Orientations used.
    pub orientations: usize,
    /// True and identified force offset \[N\].
    pub force_offset: ([f64; 3], [f64; 3]),
    /// True and identified moment offset \[N m\].
    pub moment_offset: ([f64; 3], [f64; 3]),
    /// True and identified weight \[N\].
    pub weight: (f64, f64),
    /// True and identified centre of gravity \[m\].
    pub center_of_gravity: ([f64; 3], [f64; 3]),
    /// RMS force residual \[N\].
    pub force_rms: f64,
}

fn stiffness_of(id: &StiffnessIdentification, spring: usize, axis: usize) -> (f64, f64) {
    id.axes
        .iter()
        .find(|a| a.spring == spring && a.axis == axis)
        .map(|a| match a.compliance {
            Some(c) if c > 0.0 => (1.0 / c, a.std_error / (c * c)),
            _ => (f64::NAN, f64::NAN),
        })
        .unwrap_or((f64::NAN, f64::NAN))
}

/// Whether joints `q` lie within `limits` \[rad\].
fn inside(q: &[f64], limits: &[(f64, f64)]) -> bool {
    q.iter()
        .zip(limits)
        .all(|(&v, &(lo, hi))| v >= lo && v <= hi)
}

/// The identification poses: the milling pose `q0` and two others across the workspace
/// \[rad\] (offsets on the first six joints, the second tried mirrored when it leaves
/// `limits`; a pose outside both ways is left out, so an arm with narrow ranges may be
/// identified from fewer poses).
pub fn poses(q0: &[f64], limits: &[(f64, f64)]) -> Vec<Vec<f64>> {
    const OFFSETS: [[f64; 6]; 3] = [
        [0.0; 6],
        [0.5, 0.15, -0.2, 0.6, -0.3, 0.8],
        [-0.6, -0.1, 0.25, -0.7, 0.35, -0.5],
    ];
    OFFSETS
        .iter()
        .filter_map(|o| {
            [1.0, -1.0].iter().find_map(|sign| {
                let q: Vec<f64> = q0
                    .iter()
                    .enumerate()
                    .map(|(k, q)| q + sign * o.get(k).copied().unwrap_or(0.0))
                    .collect();
                inside(&q, limits).then_some(q)
            })
        })
        .collect()
}

/// The static loads at the TCP: forces of `f` N along +-x, +-y, +-z and moments of `f / 4`
/// N m about them (a lever on the spindle), base frame.
fn loads(f: f64) -> Vec<Vector6> {
    let mut out = Vec::new();
    for k in 0..6 {
        for sign in [1.0, -1.0] {
            let mut w = Vector6::zeros();
            if let Some(v) = w.get_mut(k) {
                *v = sign * if k < 3 { f } else { 0.25 * f };
            }
            out.push(w);
        }
    }
    out
}

/// What one pose's static tests read: the frame-pair rotations per load and spring, and the
/// TCP deflection per load.
struct PoseReadings {
    rotations: Vec<(Vector6, Vec<Vector3<f64>>)>,
    tcp: Vec<(Vector6, Vector6)>,
}

/// Damping multiplier of the static tests: the arm's structural damping (2-4 % of critical)
/// times this is about critical on its first modes, so each load settles within the hold
/// (static readings do not depend on damping). The damping is stiffness-proportional, so
/// every spring also creeps with the time constant `30 beta` = 30 ms: a hold of 0.25 s leaves
/// e^-8 of the load unread.
const STATIC_DAMPING: f64 = 30.0;

/// Static tests at joints `q`: motors locked, each load ramped in 30 ms and held `id_hold`,
/// readings loaded minus unloaded with noise.
fn static_tests(
    arm: &MillingArm,
    opts: &MillingOptions,
    q: &[f64],
    seed: u64,
) -> Result<PoseReadings, SimError> {
    let mut noise = Noise::new(seed);
    let mut sim = arm.sim(q, STATIC_DAMPING, (opts.dt, opts.substeps), None)?;
    let hold = (opts.id_hold / opts.dt).round().max(1.0) as usize;
    let ramp = (0.03 / opts.dt).round().max(1.0) as usize;
    sim.step_locked(&Vector6::zeros());
    let rot0 = sim.spring_rotations();
    let tcp0 = sim.tcp_pose();
    let mut prev = Vector6::zeros();
    let mut out = PoseReadings {
        rotations: Vec::new(),
        tcp: Vec::new(),
    };
    for target in loads(opts.id_load) {
        for k in 0..ramp {
            let s = (k + 1) as f64 / ramp as f64;
            sim.step_locked(&(prev + (target - prev) * s));
        }
        for _ in 0..hold {
            sim.step_locked(&target);
        }
        prev = target;
        let rot: Vec<Vector3<f64>> = sim
            .spring_rotations()
            .iter()
            .zip(&rot0)
            .map(|(r1, r0)| (r1 - r0).map(|v| v + opts.id_noise[0] * noise.gauss()))
            .collect();
        out.rotations.push((target, rot));
        let now = sim.tcp_pose();
        let dp = now.translation.vector - tcp0.translation.vector;
        let dr = (now.rotation * tcp0.rotation.inverse()).scaled_axis();
        let mut d = Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z);
        for (k, v) in d.iter_mut().enumerate() {
            // The tracker's position noise [m]; its orientation noise over a 0.1 m target.
            let sd = if k < 3 {
                opts.id_noise[1]
            } else {
                opts.id_noise[1] / 0.1
            };
            *v += sd * noise.gauss();
        }
        out.tcp.push((target, d));
    }
    Ok(out)
}

/// Static tests in rapier at `id_poses` poses (one thread each, up to `jobs`): frame-pair
/// rotations across each virtual joint and the 6-D TCP deflection under every load; least
/// squares for each, per axis of every finite virtual joint.
pub fn identify_stiffness(
    arm: &MillingArm,
    opts: &MillingOptions,
    jobs: usize,
) -> Result<Vec<JointEstimate>, SimError> {
    let qs: Vec<Vec<f64>> = poses(&opts.q0, &arm.spec.robot.joint_limits)
        .into_iter()
        .take(opts.id_poses.clamp(1, 3))
        .collect();
    let indexed: Vec<(usize, &Vec<f64>)> = qs.iter().enumerate().collect();
    let readings = crate::workers::parallel_map(&indexed, jobs, |&(i, q)| {
        static_tests(arm, opts, q, opts.seed ^ (0x1D + i as u64))
    })?
    .into_iter()
    .collect::<Result<Vec<_>, _>>()?;
    let mut frames = Vec::new();
    let mut tcps = Vec::new();
    for (q, r) in qs.iter().zip(&readings) {
        for (w, rots) in &r.rotations {
            for (info, rot) in arm.springs.iter().zip(rots) {
                frames.push(FrameMeasurement {
                    q,
                    wrench: *w,
                    spring: info.index,
                    rotation: *rot,
                });
            }
        }
        for (w, d) in &r.tcp {
            tcps.push(TcpMeasurement {
                q,
                wrench: *w,
                deflection: *d,
                translation_only: false,
            });
        }
    }
    let e = |e: deflect_core::BuildError| SimError::new(format!("identification: {e}"));
    let by_frames = identify_from_frames(arm.model(), &frames, false).map_err(e)?;
    let by_tcp = identify_from_tcp(arm.model(), &tcps, false).map_err(e)?;
    let mut out = Vec::new();
    for info in &arm.springs {
        for (axis, &k_true) in info.k.iter().enumerate() {
            if !k_true.is_finite() {
                continue;
            }
            let (k_frames, se_frames) = stiffness_of(&by_frames, info.index, axis);
            let (k_tcp, se_tcp) = stiffness_of(&by_tcp, info.index, axis);
            out.push(JointEstimate {
                spring: info.index,
                axis,
                label: format!("{} {}", info.label, ["x", "y", "z"][axis.min(2)]),
                k_true,
                k_frames,
                se_frames,
                k_tcp,
                se_tcp,
            });
        }
    }
    Ok(out)
}

/// Sensor identification from unloaded readings (each the mean of 50 noisy samples) at
/// orientations reached by the base and wrist joints.
pub fn identify_sensor_calibration(
    arm: &MillingArm,
    opts: &MillingOptions,
) -> Result<(SensorCalibration, SensorEstimate), SimError> {
    let s2t = arm.sensor_to_tcp;
    let truth = opts.sensor.calibration(s2t);
    let mut noise = Noise::new(opts.seed ^ 0x5E);
    let mut orientations = Vec::new();
    let mut readings = Vec::new();
    for yaw in [-0.7, 0.0, 0.7] {
        for wrist in [
            [0.0, 0.0, 0.0],
            [0.8, 0.5, 0.0],
            [-0.8, -0.5, 1.0],
            [1.5, 0.3, -1.2],
        ] {
            let mut q = opts.q0.clone();
            for (k, d) in [(0usize, yaw), (3, wrist[0]), (4, wrist[1]), (5, wrist[2])] {
                if let Some(v) = q.get_mut(k) {
                    *v += d;
                }
            }
            // Only orientations the arm can take (a narrow wrist gives fewer).
            if !inside(&q, &arm.spec.robot.joint_limits) {
                continue;
            }
            let tcp = arm.forward(&q)?;
            let sensor = tcp * s2t.inverse();
            let n = 50;
            let mut mean = Vector6::zeros();
            for _ in 0..n {
                mean += opts.sensor.reading(
                    &truth,
                    &sensor,
                    &tcp.translation.vector,
                    &Vector3::zeros(),
                    &mut noise,
                    1.0,
                );
            }
            orientations.push(sensor.rotation);
            readings.push(mean / n as f64);
        }
    }
    let id = identify_sensor(&orientations, &readings, false, s2t)
        .map_err(|e| SimError::new(format!("sensor identification: {e}")))?;
    let c = &id.calibration;
    let arr = |v: &Vector3<f64>| [v.x, v.y, v.z];
    let est = SensorEstimate {
        orientations: orientations.len(),
        force_offset: (opts.sensor.force_offset, arr(&c.force_offset)),
        moment_offset: (opts.sensor.moment_offset, arr(&c.moment_offset)),
        weight: (opts.sensor.weight, c.weight),
        center_of_gravity: (opts.sensor.center_of_gravity, arr(&c.center_of_gravity)),
        force_rms: id.force_rms,
    };
    Ok((id.calibration, est))
}
