//! The milling scenario, shortened: compensation reduces the path error, pilot control reduces
//! it further (overall and at the cutter exit), and identification recovers the stiffnesses
//! and the sensor. Seconds in a debug build.

use deflect_sim::milling::{self, MillingOptions, Mode};

#[test]
fn short_milling_scenario() {
    let opts = MillingOptions::short();
    let r = milling::milling(&opts).expect("scenario");

    // Noise-free identification recovers every joint stiffness within 1 %.
    for e in &r.stiffness {
        let frames = (e.k_frames / e.k_true - 1.0).abs();
        let tcp = (e.k_tcp / e.k_true - 1.0).abs();
        assert!(frames < 0.01, "joint {} frames: {e:?}", e.joint);
        assert!(tcp < 0.01, "joint {} TCP: {e:?}", e.joint);
    }
    // Sensor: weight within 1 %, force offsets within 1 N (averaged noisy readings).
    let s = &r.sensor;
    assert!((s.weight.1 / s.weight.0 - 1.0).abs() < 0.01, "{s:?}");
    for (t, i) in s.force_offset.0.iter().zip(&s.force_offset.1) {
        assert!((t - i).abs() < 1.0, "{s:?}");
    }

    let get = |m: Mode| {
        r.runs
            .iter()
            .find(|x| x.mode == m)
            .map(|x| x.metrics)
            .expect("run")
    };
    let (u, c, p) = (
        get(Mode::Uncompensated),
        get(Mode::Cartesian),
        get(Mode::Pilot),
    );
    println!(
        "uncompensated {u:?}\ncartesian {c:?}\npilot {p:?}\n{:#?}",
        r.stiffness
    );
    // The uncompensated error is of the order of a millimetre.
    assert!(u.steady_max_mm > 0.7 && u.steady_max_mm < 1.4, "{u:?}");
    // Compensation: clear reduction of RMS and max, pilot control further.
    assert!(c.rms_mm < 0.5 * u.rms_mm, "{u:?} {c:?}");
    assert!(c.max_mm < 0.9 * u.max_mm, "{u:?} {c:?}");
    assert!(p.max_mm < 0.7 * c.max_mm, "{c:?} {p:?}");
    assert!(p.rms_mm < c.rms_mm, "{c:?} {p:?}");
    // At the cutter exit the filtered measurement lags; the estimate does not.
    assert!(p.exit_max_mm < 0.7 * c.exit_max_mm, "{c:?} {p:?}");
    // Steady cutting: both compensations remove most of the deflection.
    assert!(c.steady_max_mm < 0.3 * u.steady_max_mm, "{u:?} {c:?}");
}

#[test]
fn rapier_static_compliance_matches_vjm() {
    use deflect_core::vjm::{self, Data, Vector6};
    use deflect_sim::milling::{FlexArm, vjm_model};
    use nalgebra::Vector3;
    let opts = MillingOptions::short();
    let arm = &opts.arm;
    let q = arm.ik(&Vector3::new(1.2, 0.2, 0.0));
    let model = vjm_model(arm, &arm.stiffness).expect("model");
    let mut data = Data::new(&model);
    let f = Vector3::new(-300.0, 250.0, -200.0);
    let w = Vector6::new(f.x, f.y, f.z, 0.0, 0.0, 0.0);
    let d = vjm::deflection(&model, &mut data, &q, &w).expect("deflection");
    let mut sim = FlexArm::new(arm, &q, 4.0, opts.dt).expect("arm");
    sim.step(&q, &Vector3::zeros());
    let p0 = sim.tcp();
    for k in 0..120 {
        let s = ((k + 1) as f64 / 15.0).min(1.0);
        sim.step(&q, &(f * s));
    }
    let dp = sim.tcp() - p0;
    let err = (dp - d.fixed_rows::<3>(0)).norm() / d.fixed_rows::<3>(0).norm();
    assert!(err < 0.01, "rapier {dp:?} vs VJM {d:?}: {err}");
}

#[test]
fn milling_is_deterministic() {
    let mut opts = MillingOptions::short();
    opts.cut = 0.1;
    opts.runout = 0.05;
    let a = milling::run(
        &opts,
        Mode::Pilot,
        &milling::vjm_model(&opts.arm, &opts.arm.stiffness).expect("model"),
        &opts.sensor.calibration(opts.arm.sensor_to_tcp()),
    )
    .expect("run a");
    let b = milling::run(
        &opts,
        Mode::Pilot,
        &milling::vjm_model(&opts.arm, &opts.arm.stiffness).expect("model"),
        &opts.sensor.calibration(opts.arm.sensor_to_tcp()),
    )
    .expect("run b");
    assert_eq!(a.samples.len(), b.samples.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        assert_eq!(x.actual, y.actual);
        assert_eq!(x.correction, y.correction);
    }
}
