//! Identification before the milling runs (Hähn and Weigold, sec. 2.5-2.6): the joint
//! stiffnesses from static loads on the arm in rapier (frame-pair rotations across each
//! spring and TCP deflections, each by least squares), and the flange sensor's offsets,
//! weight and centre of gravity from unloaded readings at several orientations.

use deflect_core::compensation::SensorCalibration;
use deflect_core::identification::{
    FrameMeasurement, StiffnessIdentification, TcpMeasurement, identify_from_frames,
    identify_from_tcp, identify_sensor,
};
use deflect_core::vjm::{self, Data, Vector6};
use nalgebra::Vector3;
use serde::Serialize;

use super::arm::{FlexArm, JOINTS, vjm_model};
use super::scenario::MillingOptions;
use crate::SimError;
use crate::noise::Noise;

/// Identification of one joint's stiffness.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct JointEstimate {
    /// Joint index (0 = yaw).
    pub joint: usize,
    /// True stiffness \[N m/rad\].
    pub k_true: f64,
    /// From frame-pair rotations \[N m/rad\].
    pub k_frames: f64,
    /// Its standard error \[N m/rad\].
    pub se_frames: f64,
    /// From TCP deflections (translation only) \[N m/rad\].
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

fn stiffness_of(id: &StiffnessIdentification, joint: usize) -> (f64, f64) {
    id.axes
        .iter()
        .find(|a| a.spring == joint)
        .map(|a| match a.compliance {
            Some(c) if c > 0.0 => (1.0 / c, a.std_error / (c * c)),
            _ => (f64::NAN, f64::NAN),
        })
        .unwrap_or((f64::NAN, f64::NAN))
}

/// Static tests in rapier: at several poses, loads of `id_load` along ±x, ±y, ±z at the tool
/// point with the motors locked; frame-pair rotations across each spring and the TCP
/// translation (loaded minus unloaded), with measurement noise; least squares for each.
pub fn identify_stiffness(opts: &MillingOptions) -> Result<Vec<JointEstimate>, SimError> {
    let arm = &opts.arm;
    // The structure of the model matters, not its values.
    let guess = vjm_model(arm, &[1.0e5; JOINTS])?;
    let poses = [
        Vector3::new(1.1, -0.2, 0.1),
        Vector3::new(1.3, 0.25, 0.3),
        Vector3::new(0.9, 0.1, -0.05),
    ];
    let loads = [
        Vector3::x(),
        -Vector3::x(),
        Vector3::y(),
        -Vector3::y(),
        Vector3::z(),
        -Vector3::z(),
    ];
    let mut noise = Noise::new(opts.seed ^ 0x1D);
    let mut qs = Vec::new();
    let mut frame_data = Vec::new(); // (pose, wrench, spring, rotation)
    let mut tcp_data = Vec::new(); // (pose, wrench, deflection)
    let hold = (opts.id_hold / opts.dt).round().max(1.0) as usize;
    let ramp = (0.03 / opts.dt).round().max(1.0) as usize;
    for (pi, p) in poses.iter().take(opts.id_poses.clamp(1, 3)).enumerate() {
        let q = arm.ik(p);
        qs.push(q);
        // Critically damped (about) so that each load settles quickly.
        let mut sim = FlexArm::new(arm, &q, 4.0, opts.dt)?;
        sim.step(&q, &Vector3::zeros());
        let rot0 = sim.spring_rotations(&q);
        let tcp0 = sim.tcp();
        let mut prev = Vector3::zeros();
        for dir in &loads {
            let target = dir * opts.id_load;
            for k in 0..ramp {
                let s = (k + 1) as f64 / ramp as f64;
                sim.step(&q, &(prev + (target - prev) * s));
            }
            for _ in 0..hold {
                sim.step(&q, &target);
            }
            prev = target;
            let rot = sim.spring_rotations(&q);
            let w = Vector6::new(target.x, target.y, target.z, 0.0, 0.0, 0.0);
            for (j, (r1, r0)) in rot.iter().zip(&rot0).enumerate() {
                let mut r = r1 - r0;
                for v in r.iter_mut() {
                    *v += opts.id_noise[0] * noise.gauss();
                }
                frame_data.push((pi, w, j, r));
            }
            let mut d = sim.tcp() - tcp0;
            for v in d.iter_mut() {
                *v += opts.id_noise[1] * noise.gauss();
            }
            tcp_data.push((pi, w, Vector6::new(d.x, d.y, d.z, 0.0, 0.0, 0.0)));
        }
    }
    let frames: Vec<FrameMeasurement<'_>> = frame_data
        .iter()
        .map(|(pi, w, j, r)| FrameMeasurement {
            q: &qs[*pi],
            wrench: *w,
            spring: *j,
            rotation: *r,
        })
        .collect();
    let tcps: Vec<TcpMeasurement<'_>> = tcp_data
        .iter()
        .map(|(pi, w, d)| TcpMeasurement {
            q: &qs[*pi],
            wrench: *w,
            deflection: *d,
            translation_only: true,
        })
        .collect();
    let e = |e: deflect_core::BuildError| SimError::new(format!("identification: {e}"));
    let by_frames = identify_from_frames(&guess, &frames, false).map_err(e)?;
    let by_tcp = identify_from_tcp(&guess, &tcps, false).map_err(e)?;
    Ok((0..JOINTS)
        .map(|j| {
            let (k_frames, se_frames) = stiffness_of(&by_frames, j);
            let (k_tcp, se_tcp) = stiffness_of(&by_tcp, j);
            JointEstimate {
                joint: j,
                k_true: arm.stiffness[j],
                k_frames,
                se_frames,
                k_tcp,
                se_tcp,
            }
        })
        .collect())
}

/// Sensor identification from unloaded readings (each the mean of 50 noisy samples) at
/// orientations reached by the arm's yaw and wrist joints.
pub fn identify_sensor_calibration(
    opts: &MillingOptions,
) -> Result<(SensorCalibration, SensorEstimate), SimError> {
    let arm = &opts.arm;
    let model = vjm_model(arm, &arm.stiffness)?;
    let mut data = Data::new(&model);
    let s2t = arm.sensor_to_tcp();
    let truth = opts.sensor.calibration(s2t);
    let mut noise = Noise::new(opts.seed ^ 0x5E);
    let base = arm.ik(&Vector3::new(1.1, 0.0, 0.2));
    let mut orientations = Vec::new();
    let mut readings = Vec::new();
    for yaw in [-0.7, 0.0, 0.7] {
        for wrist in [-1.2, -0.4, 0.4, 1.2] {
            let q = [yaw, base[1], base[2], base[3] + wrist];
            let tcp = vjm::forward(&model, &mut data, &q)
                .map_err(|e| SimError::new(format!("sensor poses: {e}")))?;
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
