//! A few thousand cycles of the online compensation chain with every option on (pilot
//! control, projection onto the plane normal to the feed, axis-specific output) allocate
//! nothing: a counting global allocator watches them. One test function only.

use deflect_core::TickError;
use deflect_core::compensation::{self, CompensatorConfig, CorrectionOutput, SensorCalibration};
use deflect_core::vjm::{self, Vector6};
use nalgebra::{Isometry3, Vector3};

mod common;
mod fixtures;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn compensation_cycles_do_not_allocate() {
    common::watch_this_thread();
    common::assert_counter_works();
    // A 6R chain with a compliant virtual joint after every axis.
    let b = fixtures::six_r(fixtures::Link::Spring([3.0e6, 2.0e6, 1.0e6]));
    let chain = b.build().unwrap();
    let dt = 0.004;
    let cal = SensorCalibration {
        sensor_to_tcp: Isometry3::translation(0.0, 0.0, 0.1),
        ..SensorCalibration::default()
    };
    let mut cfg = CompensatorConfig::paper(dt, cal);
    cfg.output = CorrectionOutput::Joint;
    assert!(cfg.pilot.is_some() && cfg.project_on_feed);
    let model = compensation::Model::new(chain.clone(), cfg).unwrap();
    let mut data = compensation::Data::new(&model);
    data.reset();
    let threshold = cfg.pilot.unwrap().0;

    // 1000 N pressing along -z at the sensor; the feed runs along base y.
    let reading = Vector6::new(0.0, 0.0, -1000.0, 0.0, 0.0, 0.0);
    let feed = Vector3::new(0.0, 0.02, 0.0);
    let nan = Vector6::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut q = [0.1, -0.4, 0.9, 0.2, 0.6, -0.3];
    let mut estimate = Vector6::zeros();
    let mut out = compensation::step(&model, &mut data, &q, &reading, None, &feed).unwrap();
    let mut max_weight: f64 = 0.0;
    let mut max_correction: f64 = 0.0;
    let mut max_dq: f64 = 0.0;
    let mut weight_after_far = f64::NAN;
    let mut weight_after_agree = f64::NAN;
    let mut far_gap: f64 = 0.0;
    let mut feed_component: f64 = 0.0;
    let mut all_projected = true;
    let cycles = 4000;

    let before = common::allocations();
    for k in 0..cycles {
        // A slow joint motion, so every cycle sees a new pose.
        q[0] = 0.1 + 1e-5 * k as f64;
        q[2] = 0.9 - 5e-6 * k as f64;
        // Phases of 1000 cycles: measured only, an estimate 600 N away (pilot takes over),
        // an estimate that agrees (pilot hands back), and the far estimate again.
        let phase = k / 1000;
        let est = match phase {
            0 => None,
            1 | 3 => {
                estimate = out.measured_wrench;
                estimate[2] -= 600.0;
                Some(&estimate)
            }
            _ => {
                estimate = out.measured_wrench;
                Some(&estimate)
            }
        };
        if let Some(e) = est {
            far_gap =
                far_gap.max((out.measured_wrench.fixed_rows::<3>(0) - e.fixed_rows::<3>(0)).norm());
        }
        out = compensation::step(&model, &mut data, &q, &reading, est, &feed).unwrap();
        max_weight = max_weight.max(out.pilot_weight);
        max_correction = max_correction.max(out.correction.fixed_rows::<3>(0).norm());
        max_dq = max_dq.max(out.dq.iter().fold(0.0, |m: f64, v| m.max(v.abs())));
        feed_component = feed_component.max(out.correction[1].abs());
        all_projected &= out.projected;
        if k == 1999 {
            weight_after_far = out.pilot_weight;
        }
        if k == 2999 {
            weight_after_agree = out.pilot_weight;
        }
        // The error paths allocate nothing either, and leave the state alone.
        if k % 100 == 0 {
            let bad = compensation::step(&model, &mut data, &q, &nan, est, &feed);
            assert!(matches!(bad, Err(TickError::NonFinite { .. })));
        }
    }
    let after = common::allocations();
    assert_eq!(
        after - before,
        0,
        "allocations in {cycles} compensation cycles"
    );

    // The chain did real work: a pilot that took over, a correction, axis values.
    assert!(far_gap > threshold, "estimate differed by {far_gap} N");
    assert_eq!(
        weight_after_far, 1.0,
        "pilot takes over above the threshold"
    );
    assert_eq!(weight_after_agree, 0.0, "pilot hands back once they agree");
    assert_eq!(max_weight, 1.0);
    assert_eq!(out.pilot_weight, 1.0, "far estimate in the last phase");
    assert!(
        (out.wrench - estimate).norm() < 1e-9,
        "at full weight the wrench is the estimate: {:?}",
        out.wrench
    );
    assert!(max_correction > 1e-5, "correction {max_correction} m");
    assert!(out.correction.fixed_rows::<3>(0).norm() > 1e-5);
    assert!(max_dq > 1e-6, "dq {max_dq}");
    assert!(all_projected);
    assert!(feed_component < 1e-15, "feed component {feed_component}");
    // Axis output: J dq = correction (6 axes, non-singular pose).
    let mut vd = vjm::Data::new(&chain);
    vjm::joint_jacobian(&chain, &mut vd, &q).unwrap();
    let dq = nalgebra::Vector6::from_column_slice(&out.dq[..6]);
    let j = vd.jacobian.fixed_columns::<6>(0).into_owned();
    assert!((j * dq - out.correction).norm() < 1e-12);
}
