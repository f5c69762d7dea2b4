//! Five-axis pieces (criterion): the tri-dexel stock's ray updates per second for a ball-end
//! groove at 0 and 45 degrees of tilt (0.25 mm rays), the z-map's cell updates for the same
//! vertical groove, the cutter forces along the edge (the revolution's mean and the
//! instantaneous wrench of a ball end, tilted), APT points read per second, and the five-axis
//! job on the KR 300 per sample (a swarf cut with a flat end, a ball-end pass with 20 degrees
//! of lead: the path, the engagement from the dexels, the force along the edge, both IKs, the
//! three stocks cut).
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

/// The five-axis job on the KR 300 at the testbed's five-axis placement (the table lower and
/// closer, the wrist bent), 0.5 mm rays, 20 mm of stock.
fn job(c: &mut Criterion) {
    use deflect_core::machining::five_axis::{self, Options};
    use deflect_core::machining::job::Job;
    let mut setup =
        deflect_tests::job_setup(Vector2::new(-0.01, -0.03), Vector2::new(0.06, 0.01), 5.0e-4);
    setup.placement = nalgebra::Isometry3::new(
        Vector3::new(2.0, 0.0, 0.4),
        Vector3::new(0.0, 0.0, std::f64::consts::PI),
    );
    let robot = deflect_tests::kr300();
    let seed = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];
    let runs = [
        (
            "swarf cut, 16 mm flat end tilted 15 degrees",
            ToolShape::Flat,
            "UNITS/MM\nSPINDL/12000,CLW\nRAPID\nGOTO/-5,-22,20,0,0,1\nRAPID\n\
             GOTO/-5,-22,5,0,-0.2588190,0.9659258\nFEDRAT/MMPM,1200\n\
             GOTO/-5,-22,-3,0,-0.2588190,0.9659258\nGOTO/50,-22,-3,0,-0.2588190,0.9659258\n\
             GOTO/50,-22,10,0,0,1\nFINI\n",
        ),
        (
            "ball-end pass, 16 mm ball with 20 degrees of lead",
            ToolShape::Ball,
            "UNITS/MM\nSPINDL/12000,CLW\nRAPID\nGOTO/-5,-10,20,0,0,1\nRAPID\n\
             GOTO/-5,-10,5,-0.3420201,0,0.9396926\nFEDRAT/MMPM,1200\n\
             GOTO/-5,-10,-2,-0.3420201,0,0.9396926\nGOTO/50,-10,-2,-0.3420201,0,0.9396926\n\
             GOTO/50,-10,10,0,0,1\nFINI\n",
        ),
    ];
    let mut g = c.benchmark_group("five_axis_job");
    g.sample_size(10);
    for (name, shape, text) in runs {
        let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
        let program = apt::from_str(text, &gcode::GcodeOptions::default())
            .unwrap()
            .program;
        let options = Options {
            depth: 0.02,
            shape,
            ..Options::default()
        };
        let n = five_axis::run(&job, &program, &seed, &options)
            .unwrap()
            .samples
            .len();
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(format!("{name}, per sample"), |b| {
            b.iter(|| five_axis::run(&job, &program, &seed, &options).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench, job);
criterion_main!(benches);
