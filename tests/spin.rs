//! The spin about the tool axis chosen along the built-in job (`data/groove_and_pocket.nc` on
//! the KR 300): the schedule holds the joint limits and both rate bounds sample by sample,
//! the joints move continuously, and its predicted deflection (the exact virtual-joint
//! deflection of the runs, normal to the feed, not the search's own linearised figure) is
//! at most that of the seed's constant spin and of the best constant spin, each run in full.

use deflect_core::machining::Program;
use deflect_core::machining::job::{self, Job, Report};
use deflect_core::machining::spin::{self, LoadPath, SpinMeasure, SpinOptions, SpinSchedule};
use deflect_tests::{JOB_SEED, kr300};
use nalgebra::Vector3;

fn builtin() -> (Job, Program) {
    deflect_tests::builtin_job()
}

/// RMS over the cutting samples of the deflection normal to the feed \[m\], workpiece frame
/// (the run's exact deflection, base frame, turned back by the placement).
fn normal_rms(job: &Job, r: &Report) -> f64 {
    let back = job.setup().placement.rotation.inverse();
    let (mut sum, mut n) = (0.0, 0usize);
    for s in r.samples.iter().filter(|s| s.force.norm() > 0.0) {
        let dp = back * Vector3::new(s.deflection[0], s.deflection[1], s.deflection[2]);
        let m = SpinMeasure::Normal.of(&dp, &s.path.direction);
        sum += m * m;
        n += 1;
    }
    (sum / n as f64).sqrt()
}

#[test]
fn the_optimised_spin_deflects_least_within_the_limits_and_the_rates() {
    let (job, program) = builtin();
    let o = SpinOptions::default();
    let loads = LoadPath::new(&job, &program, o.step, o.per_metre, o.per_second).unwrap();
    let (samples, cutting) = loads.samples();
    assert_eq!(samples, 2728);
    assert!(
        cutting > 1500 && loads.stations().len() > 20,
        "{cutting} {}",
        loads.stations().len()
    );
    let plan = spin::plan(&job, &loads, &JOB_SEED, &o).unwrap();
    let seed = plan.seed.unwrap();
    let (best_angle, best) = plan.best_constant.unwrap();
    // The search's own figures: constant spins are paths of its graph.
    assert!(plan.optimised.rms <= best.rms && best.rms <= seed.rms);
    assert_eq!(plan.candidates.len(), 73);

    let optimised = job.clone().with_spin(plan.schedule.clone());
    let constant = job
        .clone()
        .with_spin(SpinSchedule::constant(best_angle).unwrap());
    let r_opt = job::run(&optimised, &program, &JOB_SEED).unwrap();
    let r_seed = job::run(&job, &program, &JOB_SEED).unwrap();
    let r_best = job::run(&constant, &program, &JOB_SEED).unwrap();
    let (e_opt, e_seed, e_best) = (
        normal_rms(&job, &r_opt),
        normal_rms(&job, &r_seed),
        normal_rms(&job, &r_best),
    );
    assert!(
        e_opt <= e_best && e_best < e_seed,
        "{e_opt:e} {e_best:e} {e_seed:e}"
    );
    assert!(
        e_opt < 0.9 * e_seed,
        "a real gain: {e_opt:e} against {e_seed:e}"
    );
    // The linearised search agrees with the exact runs to a few percent.
    assert!(
        (plan.optimised.rms - e_opt).abs() < 0.05 * e_opt,
        "{:e} {e_opt:e}",
        plan.optimised.rms
    );
    // Compensation still lands on the program.
    assert!(r_opt.path_error(true).max < 1e-7);

    // Sample by sample: the limits, the rate bounds, continuity.
    let robot = kr300();
    let (per_m, per_s) = (o.per_metre, o.per_second);
    for w in r_opt.samples.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let ds = (b.path.position - a.path.position).norm();
        let dt = b.path.time - a.path.time;
        let turned = (b.spin - a.spin).abs();
        assert!(
            turned <= per_m * ds + 1e-12,
            "t = {}: {turned} rad over {ds} m",
            b.path.time
        );
        assert!(
            turned <= per_s * dt + 1e-12,
            "t = {}: {turned} rad in {dt} s",
            b.path.time
        );
        for q in [&b.q, &b.q_commanded] {
            for (i, (v, (lo, hi))) in q.iter().zip(&robot.joint_limits).enumerate() {
                assert!(*v >= *lo && *v <= *hi, "joint {i}: {v}");
            }
        }
        let step = (0..6)
            .map(|i| (b.q_commanded[i] - a.q_commanded[i]).abs())
            .fold(0.0, f64::max);
        assert!(
            step < 0.02,
            "t = {}: a joint moves {step} rad in one sample",
            b.path.time
        );
    }
    let (lo, hi) = r_opt
        .samples
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), s| {
            (l.min(s.spin), h.max(s.spin))
        });
    assert!(
        hi - lo > 5f64.to_radians(),
        "the spin turns along the program: {lo} .. {hi}"
    );
}

#[test]
fn the_spin_options_refuse_zero_nan_and_out_of_range_bounds() {
    let (job, program) = builtin();
    let o = SpinOptions::default();
    for (what, bad) in [
        (
            "per metre",
            SpinOptions {
                per_metre: 0.0,
                ..o
            },
        ),
        (
            "per second",
            SpinOptions {
                per_second: f64::NAN,
                ..o
            },
        ),
        ("step", SpinOptions { step: 0.0, ..o }),
        ("range", SpinOptions { range: 7.0, ..o }),
        (
            "joint step",
            SpinOptions {
                max_joint_step: 0.0,
                ..o
            },
        ),
    ] {
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains("spin"), "{what}: {e}");
    }
    assert!(LoadPath::new(&job, &program, o.step, -1.0, o.per_second).is_err());
    assert!(SpinSchedule::constant(f64::INFINITY).is_err());
    // Loads built for other bounds are refused by the search.
    let loads = LoadPath::new(&job, &program, o.step, o.per_metre, o.per_second).unwrap();
    let other = SpinOptions {
        per_second: 1.0,
        ..o
    };
    assert!(spin::plan(&job, &loads, &JOB_SEED, &other).is_err());
    assert!(spin::plan(&job, &loads, &JOB_SEED[..5], &o).is_err());
    // A schedule whose spin outruns its budget is refused.
    assert!(SpinSchedule::new(vec![0.0, 0.1], vec![0.0, 0.2], 1.0, 1.0).is_err());
}
