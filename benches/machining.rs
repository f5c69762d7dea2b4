//! Criterion benchmarks of the offline machining pass on the shipped program
//! (`data/groove_and_pocket.nc`) and the KR 300, set up as `examples/07_machining_job.rs`:
//! the whole pass (throughput: program samples per second), the program driven and sampled
//! alone, and the material removal alone (throughput: z-map cell updates per second).
//! `cargo bench --bench machining`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::{self, PathOptions};
use deflect_core::machining::stock::{Cutter, ZMap};
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::units::LengthUnit;
use deflect_tests::kr300;
use nalgebra::{Isometry3, Vector2, Vector3};

fn bench(c: &mut Criterion) {
    let root = env!("CARGO_MANIFEST_DIR");
    let program = gcode::from_path(
        std::path::Path::new(&format!("{root}/data/groove_and_pocket.nc")),
        &GcodeOptions {
            start: Vector3::new(0.0, 0.0, 0.02),
            units: LengthUnit::Millimetre,
            ..GcodeOptions::default()
        },
    )
    .unwrap();
    let robot = kr300();
    let stock = Stock {
        min: Vector2::new(0.005, -0.015),
        max: Vector2::new(0.085, 0.045),
        top: 0.0,
        cell: 5.0e-4,
    };
    let setup = Setup {
        placement: Isometry3::new(
            Vector3::new(2.45, 0.02, 0.92),
            Vector3::new(0.0, 0.0, std::f64::consts::PI),
        ),
        tool_orientation: Setup::tool_down(),
        tool: Tool::new(0.016, 3, 0.0).unwrap(),
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock,
        path: PathOptions::default(),
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: job::RAPID_SKIM,
    };
    let seed = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
    let report = job::run(&job, &program, &seed).unwrap();
    let samples = path::sample(&program, &setup.path).unwrap();
    let cutter = Cutter::Flat { radius: 0.008 };
    let cut_all = || {
        let mut z = ZMap::new(stock.min, stock.max, stock.top, stock.cell).unwrap();
        let mut cells = 0usize;
        for w in samples.windows(2) {
            cells += z
                .cut(&cutter, &w[0].position, &w[1].position)
                .unwrap()
                .cells;
        }
        cells
    };
    let cells = cut_all();
    println!(
        "offline pass: {} samples, {} z-map cell updates over the three parts; material \
         removal alone: {cells} cell updates",
        report.samples.len(),
        report.cell_updates
    );
    let mut g = c.benchmark_group("machining_groove_and_pocket");
    g.sample_size(20);
    g.throughput(Throughput::Elements(report.samples.len() as u64));
    g.bench_function("offline_pass", |b| {
        b.iter(|| job::run(&job, black_box(&program), &seed).unwrap())
    });
    g.bench_function("path_sample", |b| {
        b.iter(|| path::sample(black_box(&program), &setup.path).unwrap())
    });
    g.throughput(Throughput::Elements(cells as u64));
    g.bench_function("material_removal", |b| b.iter(cut_all));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
