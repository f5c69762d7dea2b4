//! The online compensation chain (VJM paper, sections 2.2-2.6) stage by stage.

use approx::assert_relative_eq;
use deflect_core::compensation::sensor::{POLY_TERMS, orientation_quaternion, poly_terms};
use deflect_core::compensation::{
    self, CompensatorConfig, CorrectionOutput, LowPass, MovingAverage, PilotControl,
    SensorCalibration, project_normal_to_feed,
};
use deflect_core::vjm::{self, Data, Vector6};
use deflect_core::{Model, ModelBuilder};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

fn w(v: [f64; 6]) -> Vector6 {
    Vector6::from_row_slice(&v)
}

#[test]
fn lowpass_step_response_and_delay() {
    // 10 Hz at 4 ms: tau = 1/(20 pi) = 15.915 ms, alpha = 4 / 19.915 = 0.20085.
    let mut lp = LowPass::new(10.0, 0.004).unwrap();
    let tau = 1.0 / (2.0 * std::f64::consts::PI * 10.0);
    assert_relative_eq!(lp.alpha(), 0.004 / (tau + 0.004), epsilon = 1e-15);
    assert_relative_eq!(lp.delay_samples(), tau / 0.004, epsilon = 1e-12);
    assert_relative_eq!(lp.delay_seconds(), tau, epsilon = 1e-15);
    lp.step(&Vector6::zeros());
    let one = Vector6::repeat(1.0);
    for n in 1..=20 {
        let y = lp.step(&one);
        assert_relative_eq!(y[0], 1.0 - (1.0 - lp.alpha()).powi(n), epsilon = 1e-14);
    }
    // A ramp lags by the stated delay once settled.
    let mut lp = LowPass::new(10.0, 0.004).unwrap();
    let mut y = Vector6::zeros();
    for k in 0..2000 {
        y = lp.step(&Vector6::repeat(k as f64));
    }
    assert_relative_eq!(1999.0 - y[0], lp.delay_samples(), epsilon = 1e-9);
    assert!(LowPass::new(0.0, 0.004).is_err());
    assert!(LowPass::new(10.0, f64::NAN).is_err());
}

#[test]
fn moving_average_step_response_and_delay() {
    let mut ma = MovingAverage::<8>::new(5, 0.004).unwrap();
    assert_eq!(ma.delay_samples(), 2.0);
    assert_relative_eq!(ma.delay_seconds(), 0.008);
    for _ in 0..5 {
        ma.step(&Vector6::zeros());
    }
    let outs: Vec<f64> = (0..6).map(|_| ma.step(&Vector6::repeat(1.0))[3]).collect();
    assert_eq!(outs, [0.2, 0.4, 0.6, 0.8, 1.0, 1.0]);
    // A ramp comes out exactly (window - 1) / 2 samples late.
    let mut ma = MovingAverage::<8>::new(5, 0.004).unwrap();
    let mut y = 0.0;
    for k in 0..20 {
        y = ma.step(&Vector6::repeat(k as f64))[0];
    }
    assert_eq!(19.0 - y, 2.0);
    assert!(MovingAverage::<8>::new(9, 0.004).is_err());
    assert!(MovingAverage::<8>::new(0, 0.004).is_err());
}

#[test]
fn pilot_switches_exactly_above_threshold_and_ramps_over_the_set_time() {
    let dt = 0.004;
    let mut p = PilotControl::paper(dt).unwrap();
    let measured = w([100.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    // Exactly 150 N apart: trust the measurement.
    let at = w([250.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(p.step(&measured, &at), measured);
    assert_eq!(p.weight(), 0.0);
    // Just above: blend towards the estimate, 80 ms / 4 ms = 20 cycles to full weight.
    let above = w([250.0 + 1e-9, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let mut weights = Vec::new();
    for _ in 0..22 {
        let out = p.step(&measured, &above);
        weights.push(p.weight());
        assert_relative_eq!(out[0], 100.0 + p.weight() * (150.0 + 1e-9), epsilon = 1e-9);
    }
    assert_relative_eq!(weights[0], 0.05, epsilon = 1e-12);
    assert_relative_eq!(weights[18], 0.95, epsilon = 1e-9);
    assert_eq!(weights[19], 1.0);
    assert_eq!(weights[21], 1.0);
    // When they agree again it ramps back over the same time.
    for k in 1..=20 {
        p.step(&measured, &measured);
        assert_relative_eq!(p.weight(), 1.0 - 0.05 * k as f64, epsilon = 1e-9);
    }
    assert!(PilotControl::new(-1.0, 0.08, dt).is_err());
}

#[test]
fn projection_removes_exactly_the_feed_component() {
    let r = Vector3::new(0.3e-3, -0.2e-3, 0.5e-3);
    let v = Vector3::new(0.02, 0.01, 0.0);
    let (rv, ok) = project_normal_to_feed(&r, &v);
    assert!(ok);
    assert!(rv.dot(&v).abs() < 1e-20);
    // Eq. 10 by hand: r.v = 6e-6 - 2e-6 = 4e-6; v.v = 5e-4; r - 0.008 v.
    assert_relative_eq!(rv, r - v * (4e-6 / 5e-4), epsilon = 1e-18);
    let (same, ok) = project_normal_to_feed(&r, &Vector3::zeros());
    assert!(!ok);
    assert_eq!(same, r);
}

fn calibration() -> SensorCalibration {
    let mut residual = [[0.0; POLY_TERMS]; 6];
    residual[0][1] = 2.0; // F_app,x = 2 q1 + 0.5 q2 q3
    residual[0][12] = 0.5;
    residual[5][0] = 0.1;
    SensorCalibration {
        force_offset: Vector3::new(3.0, -2.0, 5.0),
        moment_offset: Vector3::new(0.2, 0.1, -0.3),
        weight: 120.0,
        center_of_gravity: Vector3::new(0.01, -0.02, 0.15),
        residual,
        sensor_to_tcp: Isometry3::new(
            Vector3::new(0.0, 0.05, 0.4),
            Vector3::new(0.0, std::f64::consts::FRAC_PI_2, 0.0),
        ),
    }
}

#[test]
fn eq18_to_20_by_hand() {
    let cal = calibration();
    // Sensor upside down (z down): gravity (0,0,-G) reads as +G along sensor z.
    let r = UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0);
    let unloaded = cal.unloaded_reading(&r);
    let q = orientation_quaternion(&r); // [0, 1, 0, 0]
    assert_relative_eq!(q[1], 1.0, epsilon = 1e-15);
    // F = F_SI + (0, 0, G) + F_app; F_app,x = 2 q1 + 0.5 q2 q3 = 0 (q1 = w = 0).
    assert_relative_eq!(unloaded[2], 5.0 + 120.0, epsilon = 1e-12);
    assert_relative_eq!(unloaded[0], 3.0, epsilon = 1e-12);
    // M = M_SI + r_G x (0, 0, G) = M_SI + (ry G, -rx G, 0) + (0, 0, 0.1).
    assert_relative_eq!(unloaded[3], 0.2 + (-0.02) * 120.0, epsilon = 1e-12);
    assert_relative_eq!(unloaded[4], 0.1 - 0.01 * 120.0, epsilon = 1e-12);
    assert_relative_eq!(unloaded[5], -0.3 + 0.1, epsilon = 1e-12);
    // Eq. 18: an external load comes back exactly.
    let ext = w([10.0, -20.0, 30.0, 1.0, 2.0, 3.0]);
    assert_relative_eq!(cal.compensate(&(unloaded + ext), &r), ext, epsilon = 1e-12);
    // Eq. 19-20: force (10, -20, 30) at a TCP 0.05 y, 0.4 z away: M_TCP = M - r x F.
    let r_st = Vector3::new(0.0, 0.05, 0.4);
    let m_tcp = Vector3::new(1.0, 2.0, 3.0) - r_st.cross(&Vector3::new(10.0, -20.0, 30.0));
    let tcp = cal.to_tcp_frame(&ext);
    // TCP frame = sensor frame turned +90 deg about y: x_tcp = -z_s, z_tcp = x_s.
    assert_relative_eq!(tcp[0], -30.0, epsilon = 1e-12);
    assert_relative_eq!(tcp[1], -20.0, epsilon = 1e-12);
    assert_relative_eq!(tcp[2], 10.0, epsilon = 1e-12);
    assert_relative_eq!(tcp[3], -m_tcp.z, epsilon = 1e-12);
    assert_relative_eq!(tcp[5], m_tcp.x, epsilon = 1e-12);
    // Eq. 17 terms.
    let t = poly_terms(&[0.5, 0.5, 0.5, 0.5]);
    assert_eq!(t.len(), 15);
    assert_eq!(t[0], 1.0);
    assert_eq!(t[14], 0.25);
}

fn arm() -> Model {
    ModelBuilder::new()
        .fixed(Isometry3::translation(0.0, 0.0, 0.5))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .spring([4.0e6, 4.0e6, 2.0e6])
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .spring([3.0e6, 1.0e6, 3.0e6])
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .spring([2.0e6, 6.0e5, 2.0e6])
        .unwrap()
        .fixed(Isometry3::translation(0.8, 0.0, -0.2))
        .unwrap()
        .build()
        .unwrap()
}

#[test]
fn compensator_steady_state_cancels_the_model_deflection() {
    let model = arm();
    let dt = 0.004;
    let cal = SensorCalibration {
        sensor_to_tcp: Isometry3::translation(0.0, 0.0, 0.2),
        ..SensorCalibration::default()
    };
    let mut cfg = CompensatorConfig::paper(dt, cal);
    cfg.project_on_feed = false;
    cfg.max_rate = 1.0;
    let comp = compensation::Model::new(model.clone(), cfg).unwrap();
    let mut cdata = compensation::Data::new(&comp);
    // Delay of the paper chain: low-pass tau/dt + (5 - 1)/2.
    let tau = 1.0 / (2.0 * std::f64::consts::PI * 10.0);
    assert_relative_eq!(comp.delay_samples(), tau / dt + 2.0, epsilon = 1e-9);
    let q = [0.2, -0.3, 0.9];
    let mut data = Data::new(&model);
    let tcp = vjm::forward(&model, &mut data, &q).unwrap();
    // An external TCP force of 400 N along base x, seen by a sensor at the TCP's orientation.
    let f_base = Vector3::new(400.0, 0.0, 0.0);
    let r_bs = tcp.rotation * cal.sensor_to_tcp.rotation.inverse();
    let f_s = r_bs.inverse() * f_base;
    let m_s = cal.sensor_to_tcp.translation.vector.cross(&f_s);
    let reading = w([f_s.x, f_s.y, f_s.z, m_s.x, m_s.y, m_s.z]);
    let mut out = None;
    for _ in 0..400 {
        out = Some(
            compensation::step(&comp, &mut cdata, &q, &reading, None, &Vector3::zeros()).unwrap(),
        );
    }
    let out = out.unwrap();
    assert_relative_eq!(
        out.wrench,
        w([400.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        epsilon = 1e-9
    );
    let d = vjm::deflection(&model, &mut data, &q, &out.wrench, vjm::Load::Exact).unwrap();
    assert_relative_eq!(out.correction, -d, epsilon = 1e-15);
    assert!(!out.size_limited && !out.rate_limited);

    // Joint output: J dq = correction.
    let mut cfg_j = cfg;
    cfg_j.output = CorrectionOutput::Joint;
    cfg_j.max_rate = 10.0;
    let comp = compensation::Model::new(model.clone(), cfg_j).unwrap();
    let mut cdata = compensation::Data::new(&comp);
    let mut out =
        compensation::step(&comp, &mut cdata, &q, &reading, None, &Vector3::zeros()).unwrap();
    for _ in 0..400 {
        out = compensation::step(&comp, &mut cdata, &q, &reading, None, &Vector3::zeros()).unwrap();
    }
    vjm::joint_jacobian(&model, &mut data, &q).unwrap();
    let j = data.jacobian.fixed_columns::<3>(0).into_owned();
    let dq = nalgebra::Vector3::new(out.dq[0], out.dq[1], out.dq[2]);
    // A 3-joint arm reaches the translation part in the least-squares sense: J^T (J dq - c) = 0.
    let resid = j * dq - out.correction;
    assert!((j.transpose() * resid).norm() < 1e-15, "{resid:?}");
}

#[test]
fn compensator_limits_and_pilot_are_reported() {
    let model = arm();
    let dt = 0.004;
    let mut cfg = CompensatorConfig::paper(dt, SensorCalibration::default());
    cfg.max_correction = 0.1e-3;
    cfg.max_rate = 0.01; // 40 um per cycle
    let comp = compensation::Model::new(model.clone(), cfg).unwrap();
    let mut cdata = compensation::Data::new(&comp);
    let q = [0.2, -0.3, 0.9];
    let reading = w([0.0, 0.0, -2000.0, 0.0, 0.0, 0.0]);
    let feed = Vector3::new(0.0, 0.025, 0.0);
    let first = compensation::step(&comp, &mut cdata, &q, &reading, None, &feed).unwrap();
    assert!(first.rate_limited);
    assert_relative_eq!(
        first.correction.fixed_rows::<3>(0).norm(),
        40e-6,
        epsilon = 1e-12
    );
    assert!(first.projected);
    assert!(
        first.correction[1].abs() < 1e-18,
        "feed (y) component removed"
    );
    let mut last = first;
    for _ in 0..100 {
        last = compensation::step(&comp, &mut cdata, &q, &reading, None, &feed).unwrap();
    }
    assert!(last.size_limited && !last.rate_limited);
    assert_relative_eq!(
        last.correction.fixed_rows::<3>(0).norm(),
        0.1e-3,
        epsilon = 1e-12
    );
    // Pilot control: an estimate 500 N away takes over within 80 ms (20 cycles).
    let est = w([0.0, 0.0, -2500.0, 0.0, 0.0, 0.0]);
    let mut o = last;
    for _ in 0..20 {
        o = compensation::step(&comp, &mut cdata, &q, &reading, Some(&est), &feed).unwrap();
    }
    assert_eq!(o.pilot_weight, 1.0);
    assert!(o.wrench[2] < -2400.0);
    // Bad input is a typed error, not a panic.
    let nan = w([f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert!(compensation::step(&comp, &mut cdata, &q, &nan, None, &feed).is_err());
    assert!(compensation::step(&comp, &mut cdata, &q[..2], &reading, None, &feed).is_err());
    let mut bad = cfg;
    bad.moving_average_window = 0;
    assert!(compensation::Model::new(model, bad).is_err());
}
