//! Latency harness: per-tick wall time of the real-time paths over 1e6 consecutive ticks,
//! reported as median, p99.9 and max (a mean hides the tail a servo loop cares about).
//! `cargo bench --bench latency` (optionally `-- N` ticks).

use std::hint::black_box;

use deflect_core::compensation::{self, CompensatorConfig, SensorCalibration};
use deflect_core::dalembert::{self, serial};
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::vjm::{self, Data, Vector6};
use deflect_tests::{KR300_MILLING_POSE, MILLING_WRENCH, kr300, latency_report};
use nalgebra::Vector3;

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
        black_box(vjm::deflection(model, &mut data, black_box(&q), &w, vjm::Load::Exact).ok());
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
    let one_shot = dalembert::parallel::Model::new(robot2, view, 5.0).expect("valid corrector");
    let fixed_point = one_shot.clone().with_fixed_point(3, 0.0).expect("valid");
    for (name, corr) in [
        ("dalembert tick (one-shot)", one_shot),
        ("dalembert tick (3 fixed-pt)", fixed_point),
    ] {
        let mut data = dalembert::parallel::Data::new(&corr);
        latency_report(name, n, Some(budget), |i| {
            // Tick-by-tick sampling at 2 kHz, wrapping around the 375 ms motion.
            let t = (i as f64 / 2000.0) % period;
            let s = traj.sample(black_box(t)).expect("in range");
            if let Ok(tick) =
                dalembert::parallel::step(&corr, &mut data, &s.position, &s.acceleration)
            {
                black_box(tick.joints);
            }
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
        let comp = compensation::Model::new(model.clone(), cfg).expect("valid config");
        let mut cdata = compensation::Data::new(&comp);
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
                compensation::step(
                    &comp,
                    &mut cdata,
                    &q,
                    black_box(&reading),
                    Some(&estimated),
                    &feed,
                )
                .ok(),
            );
        });
    }

    // The 6-D D'Alembert corrector of a serial arm on the KR 300 (150 kg payload): inertial
    // wrench -> loaded pose IK (exact VJM deflection) warm-started from the last ticks, along
    // a 0.33 m / 0.3 rad pose motion at about 1 g, wrapping around; the payload alone (the
    // paper's D'Alembert force) and with the links' own inertia (the URDF's masses).
    let serial = serial::Model::new(
        model.clone(),
        serial::Payload {
            mass: 150.0,
            com: nalgebra::Vector3::new(0.0, 0.0, 0.25),
            inertia: nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(4.0, 4.0, 2.5)),
        },
    )
    .expect("valid corrector")
    .with_joint_limits(&robot.joint_limits)
    .expect("limits");
    let traj = deflect_tests::kr300_pose_motion();
    let rate = 2000.0;
    let count = traj.tick_count(rate).expect("ticks");
    let states: Vec<_> = (0..count)
        .map(|k| traj.sample(traj.tick_time(rate, k, count)).expect("sample"))
        .collect();
    for (name, corrector) in [
        ("serial 6-D tick (KR 300, payload)", serial.clone()),
        (
            "serial 6-D tick (KR 300, +links)",
            serial.with_link_inertia(true),
        ),
    ] {
        let mut sdata = serial::Data::new(&corrector);
        sdata.set_seed(&KR300_MILLING_POSE);
        let mut back = false;
        latency_report(name, n, Some(budget), |i| {
            // Forth and back along the motion, so the warm start follows a smooth path.
            let k = i % count;
            if k == 0 {
                back = !back;
            }
            let s = if back {
                &states[count - 1 - k]
            } else {
                &states[k]
            };
            if let Ok(tick) = serial::step(&corrector, &mut sdata, black_box(s), None) {
                black_box(tick.joints);
            }
        });
    }

    // The same payload through the paper's generic corrector (`dalembert::parallel`): the
    // arm as a position-only mechanism (damped-least-squares IK of the TCP point) and its
    // VJM as the displacement model, iterated to the fixed point c = x_d - d(c, F) within
    // 1e-9 m, against the serial corrector's one loaded pose IK. Both carry a 150 kg point
    // mass at the TCP along the same motion; the generic form solves only the translation
    // (3-D), the serial one the whole pose (6-D). Why dalembert keeps two correctors.
    let point = serial::Model::new(
        model.clone(),
        serial::Payload::point(150.0, nalgebra::Vector3::zeros()),
    )
    .expect("valid corrector");
    let mut pdata = serial::Data::new(&point);
    pdata.set_seed(&KR300_MILLING_POSE);
    let arm = deflect_core::mechanism::SerialArm::<6>::new(
        model.clone(),
        deflect_core::mechanism::IkOptions::default(),
    )
    .expect("6 joints");
    let vjm_model = deflect_tests::VjmDisplacement {
        model: model.clone(),
        moment: nalgebra::Vector3::zeros(),
    };
    let generic = dalembert::parallel::Model::new(arm, vjm_model, 150.0)
        .and_then(|m| m.with_fixed_point(dalembert::parallel::MAX_FIXED_POINT_ITERATIONS, 1e-9))
        .expect("valid corrector");
    let mut gdata = dalembert::parallel::Data::new(&generic);
    gdata.set_seed(nalgebra::SVector::<f64, 6>::from_row_slice(
        &KR300_MILLING_POSE,
    ));
    let forth_and_back = |i: usize| {
        let k = i % (2 * count);
        if k < count { k } else { 2 * count - 1 - k }
    };
    latency_report(
        "serial 6-D tick (KR 300, point mass)",
        n / 10,
        Some(budget),
        |i| {
            let s = &states[forth_and_back(i)];
            if let Ok(tick) = serial::step(&point, &mut pdata, black_box(s), None) {
                black_box(tick.joints);
            }
        },
    );
    latency_report(
        "generic 3-D tick (KR 300, point mass)",
        n / 10,
        Some(budget),
        |i| {
            let s = &states[forth_and_back(i)];
            let (x, a) = (s.pose.translation.vector, s.acceleration);
            if let Ok(tick) = dalembert::parallel::step(&generic, &mut gdata, black_box(&x), &a) {
                black_box(tick.joints);
            }
        },
    );
}
