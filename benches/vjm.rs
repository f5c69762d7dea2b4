//! Criterion benchmarks of the virtual-joint model on the shipped KR 300 (6 joints,
//! 11 virtual joints). `cargo bench --bench vjm`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use deflect_core::vjm::{self, Data, Vector6};
use deflect_tests::{KR300_MILLING_POSE, MILLING_WRENCH, kr300};

fn bench(c: &mut Criterion) {
    let robot = kr300();
    let model = &robot.model;
    let mut data = Data::new(model);
    let q = KR300_MILLING_POSE;
    let w = Vector6::from_row_slice(&MILLING_WRENCH);
    let mut g = c.benchmark_group("vjm_kr300");
    g.bench_function("forward", |b| {
        b.iter(|| vjm::forward(model, &mut data, black_box(&q)))
    });
    g.bench_function("deflection", |b| {
        b.iter(|| {
            vjm::deflection(
                model,
                &mut data,
                black_box(&q),
                black_box(&w),
                vjm::Load::Exact,
            )
        })
    });
    g.bench_function("compliance", |b| {
        b.iter(|| vjm::compliance(model, &mut data, black_box(&q)))
    });
    g.bench_function("joint_jacobian", |b| {
        b.iter(|| vjm::joint_jacobian(model, &mut data, black_box(&q)))
    });
    g.bench_function("joint_correction_1_step", |b| {
        b.iter(|| vjm::joint_correction(model, &mut data, black_box(&q), black_box(&w), 1, 0.0))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
