//! The jerk-limited planner natively against ruckig's Rust port (`rsruckig`, a dev-dependency
//! of this bench only), each called as its own documentation calls it: ruckig's `Ruckig`,
//! `InputParameter` and `Trajectory` built and the input filled once, `calculate` per plan;
//! deflect's `Limits` built once, `Trajectory::line` per plan, and one trajectory re-planned
//! in place per plan (`replan_line`, ruckig's habit; `replan_line_with` under limits
//! prepared once, as Python's `LinePlanner` plans); the profile solve alone too.
//! A 1-D move, and the paper's 150 mm y-line (x held: per-axis and path limits coincide).
//! `cargo bench --bench planner`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use deflect_core::motion::{Limits, PreparedLimits, Profile, Trajectory};
use nalgebra::{Vector1, Vector2};
use rsruckig::prelude::*;

const V: f64 = 1.2;
const A: f64 = 25.0;
const J: f64 = 600.0;

fn ruckig_objects<const N: usize>(
    start: [f64; N],
    end: [f64; N],
) -> (
    Ruckig<N, ThrowErrorHandler>,
    InputParameter<N>,
    rsruckig::prelude::Trajectory<N>,
) {
    let otg = Ruckig::<N, ThrowErrorHandler>::new(None, 0.0005);
    let mut input = InputParameter::new(None);
    for k in 0..N {
        input.current_position[k] = start[k];
        input.target_position[k] = end[k];
        input.max_velocity[k] = V;
        input.max_acceleration[k] = A;
        input.max_jerk[k] = J;
    }
    (otg, input, rsruckig::prelude::Trajectory::new(None))
}

fn bench(c: &mut Criterion) {
    let limits = Limits::new(V, A, J).unwrap();
    let mut group = c.benchmark_group("planner");

    // 1-D: 0.05 -> 0.35.
    let (mut otg, input, mut traj) = ruckig_objects([0.05], [0.35]);
    otg.calculate(&input, &mut traj).unwrap();
    let ours = Trajectory::line(Vector1::new(0.05), Vector1::new(0.35), &limits).unwrap();
    assert!((ours.duration() - traj.get_duration()).abs() < 1e-12 * traj.get_duration());
    group.bench_function("1d/ruckig_calculate", |b| {
        b.iter(|| otg.calculate(black_box(&input), &mut traj).unwrap())
    });
    group.bench_function("1d/deflect_line", |b| {
        b.iter(|| {
            Trajectory::line(
                black_box(Vector1::new(0.05)),
                black_box(Vector1::new(0.35)),
                &limits,
            )
            .unwrap()
            .duration()
        })
    });
    // ruckig's own habit: one trajectory object, re-planned in place per move.
    let mut mine = ours.clone();
    group.bench_function("1d/deflect_replan_line", |b| {
        b.iter(|| {
            mine.replan_line(
                black_box(Vector1::new(0.05)),
                black_box(Vector1::new(0.35)),
                &limits,
            )
            .unwrap();
            mine.duration()
        })
    });
    let prepared = PreparedLimits::new(&limits).unwrap();
    group.bench_function("1d/deflect_replan_line_with", |b| {
        b.iter(|| {
            mine.replan_line_with(
                black_box(Vector1::new(0.05)),
                black_box(Vector1::new(0.35)),
                &prepared,
            )
            .unwrap();
            mine.duration()
        })
    });
    group.bench_function("1d/deflect_profile_solve", |b| {
        b.iter(|| Profile::new(black_box(0.3), &limits).unwrap().duration())
    });

    // The paper's y-line, 150 mm at x = 0.22 m.
    let (mut otg2, input2, mut traj2) = ruckig_objects([0.22, -0.075], [0.22, 0.075]);
    otg2.calculate(&input2, &mut traj2).unwrap();
    let ours2 = Trajectory::line(
        Vector2::new(0.22, -0.075),
        Vector2::new(0.22, 0.075),
        &limits,
    )
    .unwrap();
    assert!((ours2.duration() - traj2.get_duration()).abs() < 1e-12 * traj2.get_duration());
    group.bench_function("2d_y_line/ruckig_calculate", |b| {
        b.iter(|| otg2.calculate(black_box(&input2), &mut traj2).unwrap())
    });
    group.bench_function("2d_y_line/deflect_line", |b| {
        b.iter(|| {
            Trajectory::line(
                black_box(Vector2::new(0.22, -0.075)),
                black_box(Vector2::new(0.22, 0.075)),
                &limits,
            )
            .unwrap()
            .duration()
        })
    });
    let mut mine2 = ours2.clone();
    group.bench_function("2d_y_line/deflect_replan_line", |b| {
        b.iter(|| {
            mine2
                .replan_line(
                    black_box(Vector2::new(0.22, -0.075)),
                    black_box(Vector2::new(0.22, 0.075)),
                    &limits,
                )
                .unwrap();
            mine2.duration()
        })
    });
    group.bench_function("2d_y_line/deflect_replan_line_with", |b| {
        b.iter(|| {
            mine2
                .replan_line_with(
                    black_box(Vector2::new(0.22, -0.075)),
                    black_box(Vector2::new(0.22, 0.075)),
                    &prepared,
                )
                .unwrap();
            mine2.duration()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
