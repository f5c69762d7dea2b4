//! Five-axis pieces (criterion): the tri-dexel stock's ray updates per second for a ball-end
//! groove at 0 and 45 degrees of tilt (0.25 mm rays), the z-map's cell updates for the same
//! vertical groove, the cutter forces along the edge (the revolution's mean and the
//! instantaneous wrench of a ball end, tilted), and APT points read per second.
//!
//! `cargo bench --bench five_axis`

use std::fmt::Write as _;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use deflect_core::io::{apt, gcode};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::dexel::{DexelTool, Dexels};
use deflect_core::machining::profile::{self, Band, Cut, Profile, ToolShape};
use deflect_core::machining::stock::{Cutter, ZMap};
use nalgebra::{Vector2, Vector3};

fn bench(c: &mut Criterion) {
    let tool = Tool::new(6e-3, 2, 0.5).unwrap();
    let ball = Profile::new(&tool, ToolShape::Ball).unwrap();
    let dexel_tool = DexelTool::new(&ball, 10e-3).unwrap();
    let block = || {
        Dexels::block(
            Vector3::new(0.0, -8e-3, -8e-3),
            Vector3::new(20e-3, 8e-3, 0.0),
            0.25e-3,
        )
        .unwrap()
    };
    let (from, to) = (
        Vector3::new(3e-3, 0.0, -2e-3),
        Vector3::new(17e-3, 0.0, -2e-3),
    );
    let mut g = c.benchmark_group("dexel");
    g.sample_size(10);
    for degrees in [0.0f64, 45.0] {
        let t = degrees.to_radians();
        let axis = Vector3::new(0.0, t.sin(), t.cos());
        let rays = block()
            .cut(&dexel_tool, &from, &axis, &to, &axis)
            .unwrap()
            .rays;
        g.throughput(Throughput::Elements(rays as u64));
        g.bench_function(
            format!("ball groove at {degrees} deg, per ray updated"),
            |b| {
                b.iter_batched(
                    block,
                    |mut d| d.cut(&dexel_tool, &from, &axis, &to, &axis).unwrap(),
                    criterion::BatchSize::LargeInput,
                )
            },
        );
    }
    g.finish();

    let mut g = c.benchmark_group("zmap");
    let zmap = || {
        ZMap::new(
            Vector2::new(0.0, -8e-3),
            Vector2::new(20e-3, 8e-3),
            0.0,
            0.25e-3,
        )
        .unwrap()
    };
    let cells = zmap()
        .cut(&Cutter::Ball { radius: 3e-3 }, &from, &to)
        .unwrap()
        .cells;
    g.throughput(Throughput::Elements(cells as u64));
    g.bench_function("ball groove, per cell updated", |b| {
        b.iter_batched(
            zmap,
            |mut z| z.cut(&Cutter::Ball { radius: 3e-3 }, &from, &to).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    g.finish();

    let k = Coefficients::AL7075_T6_CARBIDE;
    let bands = [
        Band::new(2e-3, 0.3, 3.0),
        Band {
            bottom: 2e-3,
            top: 4e-3,
            entry: 1.0,
            exit: 3.1,
        },
    ];
    let cut = Cut {
        bands: &bands,
        feed: Vector3::new(0.1e-3 * 0.966, 0.0, 0.1e-3 * 0.259),
    };
    let mut g = c.benchmark_group("cutter force");
    g.bench_function("ball end, tilted: revolution mean", |b| {
        b.iter(|| profile::average(&k, &ball, &cut).unwrap())
    });
    g.bench_function("ball end, tilted: instantaneous", |b| {
        b.iter(|| profile::force(&k, &ball, &cut, 0.7).unwrap())
    });
    g.finish();

    let mut text = String::from("UNITS/MM\nMULTAX\nFEDRAT/MMPM,1200\n");
    let n: u32 = 10_000;
    for i in 0..n {
        let t = f64::from(i) / f64::from(n);
        let lean = (30.0 * t).to_radians();
        writeln!(
            text,
            "GOTO/{:.6},{:.6},{:.6},{:.9},{:.9},{:.9}",
            100.0 * t,
            5.0 * (9.0 * t).sin(),
            2.0,
            lean.sin(),
            0.0,
            lean.cos()
        )
        .unwrap();
    }
    let mut g = c.benchmark_group("apt");
    g.throughput(Throughput::Elements(u64::from(n)));
    g.bench_function("read, per GOTO with a tool vector", |b| {
        b.iter(|| apt::from_str(&text, &gcode::GcodeOptions::default()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
