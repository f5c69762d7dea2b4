//! Latency harness: per-tick wall time of the real-time paths over 1e6 consecutive ticks,
//! reported as median, p99.9 and max (a mean hides the tail a servo loop cares about).
//! `cargo bench --bench latency` (optionally `-- N` ticks).

use std::hint::black_box;

use deflect_core::compensation::{CompensatorConfig, OnlineCompensator, SensorCalibration};
use deflect_core::dalembert::DalembertCorrector;
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::vjm::{self, Data, Vector6};
use deflect_tests::{KR300_MILLING_POSE, MILLING_WRENCH, kr300, latency_report};
use nalgebra::{Vector2, Vector3};

fn main() {
    let rt = deflect_tests::realtime_setup();
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    // A 2 kHz servo tick leaves 500 us for everything.
    let budget = 500_000.0;
    let robot = kr300();
    let model = &robot.model;
    let mut data = Data::new(model);
    let w = Vector6::from_row_slice(&MILLING_WRENCH);
    let mut q = KR300_MILLING_POSE;
    println!("deflect latency harness ({rt}); KR 300 model (6 joints, 11 virtual joints)");
    latency_report("vjm::deflection", n, Some(budget), |i| {
        q[0] = 1e-6 * (i % 1000) as f64;
        black_box(vjm::deflection(model, &mut data, black_box(&q), &w).ok());
    });
    latency_report("vjm::compliance", n, Some(budget), |i| {
        q[0] = 1e-6 * (i % 1000) as f64;
        black_box(vjm::compliance(model, &mut data, black_box(&q)).ok());
    });
    latency_report("vjm::joint_correction(1)", n / 10, Some(budget), |i| {
        q[0] = 1e-6 * (i % 1000) as f64;
        black_box(vjm::joint_correction(model, &mut data, black_box(&q), &w, 1, 0.0).ok());
    });

    // The 2 kHz D'Alembert loop of the parallel robot: plan (sample the jerk-limited profile)
    // -> F_D = -m* a -> compliance map -> corrected point -> closed-form IK.
    let map = deflect_tests::paper_oc_map_clamped();
    let view = map.view();
    let robot2 = ParallelRobot2::paper();
    let traj = deflect_tests::paper_y_line_5g();
    let period = traj.duration();
    for (name, corr) in [
        (
            "dalembert tick (one-shot)",
            DalembertCorrector::new(5.0).expect("mass"),
        ),
        (
            "dalembert tick (3 fixed-pt)",
            DalembertCorrector::new(5.0)
                .expect("mass")
                .with_fixed_point(3, 0.0),
        ),
    ] {
        let mut q2 = Vector2::zeros();
        latency_report(name, n, Some(budget), |i| {
            // Tick-by-tick sampling at 2 kHz, wrapping around the 375 ms motion.
            let t = (i as f64 / 2000.0) % period;
            let s = traj.sample(black_box(t)).expect("in range");
            if let Ok(tick) = corr.step(&robot2, &view, &s.position, &s.acceleration, &q2) {
                q2 = tick.joints;
            }
            black_box(q2);
        });
    }

    // The online compensation cycle of the VJM paper on the KR 300 (sensor processing,
    // low-pass + moving average, pilot control, VJM deflection, projection, limits) at the
    // paper's 4 ms cycle and at 2 kHz; the cost per cycle does not depend on the rate.
    for (name, dt) in [
        ("compensation cycle (4 ms)", 0.004),
        ("compensation cycle (2 kHz)", 0.0005),
    ] {
        let cfg = CompensatorConfig::paper(dt, SensorCalibration::default());
        let mut comp = OnlineCompensator::new(model, cfg).expect("valid config");
        let feed = Vector3::new(0.0, 0.025, 0.0);
        let estimated = Vector6::from_row_slice(&MILLING_WRENCH);
        latency_report(name, n, Some(budget), |i| {
            // A cutter exit every 250 cycles: the reading drops to zero.
            let reading = if (i / 250) % 2 == 0 {
                w
            } else {
                Vector6::zeros()
            };
            black_box(
                comp.step(model, &q, black_box(&reading), Some(&estimated), &feed)
                    .ok(),
            );
        });
    }
}
