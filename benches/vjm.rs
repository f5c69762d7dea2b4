//! Criterion benchmarks of the virtual-joint model on the shipped KR 300 (6 joints,
//! 11 virtual joints), and on the UR5 of example-robot-data (6 joints, one spring each: the
//! chain `benches/peers.py` times from Python) when `DEFLECT_UR5_URDF` names its URDF
//! (`benches/peers.py --ur5-path` prints it). `cargo bench --bench vjm`.

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
    ur5(c);
}

/// The UR5 calls of `benches/peers.py`, natively: what the Python binding adds is the
/// difference.
fn ur5(c: &mut Criterion) {
    let Ok(urdf) = std::env::var("DEFLECT_UR5_URDF") else {
        eprintln!("vjm_ur5: skipped (set DEFLECT_UR5_URDF to the UR5 URDF of example-robot-data)");
        return;
    };
    let stiffness = deflect_tests::repo_path("robots/ur5/ur5_stiffness.toml");
    let robot = match deflect_core::SerialRobot::from_path(&urdf, &stiffness, "tool0") {
        Ok(r) => r,
        Err(e) => panic!("DEFLECT_UR5_URDF={urdf}: {e}"),
    };
    let model = &robot.model;
    let mut data = Data::new(model);
    // The joints and wrench of benches/peers.py.
    let q = [0.0, -1.2, 1.4, -0.7, 1.1, 0.3];
    let w = Vector6::new(30.0, -20.0, 50.0, 2.0, -1.0, 0.5);
    let mut g = c.benchmark_group("vjm_ur5");
    for (name, load) in [
        ("linear_deflection", vjm::Load::Linearized),
        ("deflection", vjm::Load::Exact),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| vjm::deflection(model, &mut data, black_box(&q), black_box(&w), load))
        });
    }
    g.bench_function("linear_deflection_alone", |b| {
        b.iter(|| vjm::linear_deflection(model, &mut data, black_box(&q), black_box(&w)))
    });
    g.bench_function("compliance", |b| {
        b.iter(|| vjm::compliance(model, &mut data, black_box(&q)))
    });
    // The rows of `deflection_batch` in benches/peers.py: joints uniform in [-2, 2] rad,
    // wrenches in [-50, 50] N and N m (a deterministic generator), 1024 rows per iteration.
    let mut uniform = deflect_tests::uniform(0x2545_f491_4f6c_dd1d);
    let rows: Vec<([f64; 6], Vector6)> = (0..1024)
        .map(|_| {
            let q = [0; 6].map(|_| uniform(-2.0, 2.0));
            let w = Vector6::from_fn(|_, _| uniform(-50.0, 50.0));
            (q, w)
        })
        .collect();
    g.bench_function("deflection_1024_random_rows", |b| {
        b.iter(|| {
            for (q, w) in &rows {
                let _ = black_box(vjm::deflection(model, &mut data, q, w, vjm::Load::Exact));
            }
        })
    });
    // The same rows four at a time (`deflection_batch`'s path), each row's bits the same.
    g.bench_function("exact_deflection_x4_1024_random_rows", |b| {
        b.iter(|| {
            for four in rows.chunks_exact(4) {
                let q = [0, 1, 2, 3].map(|r| four[r].0.as_slice());
                let w = [0, 1, 2, 3].map(|r| &four[r].1);
                let _ = black_box(vjm::exact_deflection_x4(model, &data, q, w));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
