//! The spin search and the placement search on the KR 300 (criterion): the program's loads
//! (the nominal pass, once), the spin search over the built-in job per sample of the run
//! (73 candidates, 1 degree/mm, 30 degrees/s), and placements scored per second with the
//! seed's spin and with the spin search, on one thread and on two.
//!
//! `cargo bench --bench spin_placement`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use deflect_core::machining::placement::{PlacementBox, Problem};
use deflect_core::machining::spin::{self, LoadPath, SpinOptions};
use deflect_tests::JOB_SEED;

fn bench(c: &mut Criterion) {
    let (job, program) = deflect_tests::builtin_job();
    let o = SpinOptions::default();
    let loads = LoadPath::new(&job, &program, o.step, o.per_metre, o.per_second).unwrap();
    let (samples, _) = loads.samples();
    let mut g = c.benchmark_group("spin");
    g.throughput(Throughput::Elements(samples as u64));
    g.bench_function("loads (nominal pass), per sample", |b| {
        b.iter(|| LoadPath::new(&job, &program, o.step, o.per_metre, o.per_second).unwrap())
    });
    g.bench_function("search (73 candidates), per sample", |b| {
        b.iter(|| spin::plan(&job, &loads, &JOB_SEED, &o).unwrap())
    });
    g.finish();

    let bx = PlacementBox {
        min: [2.35, -0.1, 0.9, -0.2],
        max: [2.45, 0.1, 0.94, 0.2],
        steps: [4, 4, 1, 2],
    };
    let grid = bx.grid();
    let mut g = c.benchmark_group("placement");
    g.sample_size(10);
    g.throughput(Throughput::Elements(grid.len() as u64));
    for optimise in [false, true] {
        let p = Problem::new(job.clone(), &program, &JOB_SEED, o, optimise).unwrap();
        for threads in [1, 2] {
            let name = format!(
                "{} spin, {threads} thread{}, per placement",
                if optimise { "optimised" } else { "seed's" },
                if threads == 1 { "" } else { "s" }
            );
            g.bench_function(&name, |b| b.iter(|| p.evaluate_all(&grid, threads)));
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
