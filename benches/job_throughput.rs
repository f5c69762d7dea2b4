//! Throughput of the offline machining pass (`machining::job::run_streaming`) on the KR 300,
//! in samples per second and z-map cell updates per second, on one thread and on two: the
//! built-in job (`data/groove_and_pocket.nc`, 16 mm flat end mill) and a 3-D raster of a
//! wavy floor (10 mm ball end mill, 0.5 mm stepover, 502,000 samples at 250 Hz). Each job
//! runs `DEFLECT_BENCH_REPEAT` times (3); the best run is printed, with the peak resident
//! memory of the process.
//!
//! `DEFLECT_BENCH_HOURS=8` adds a raster of that many hours of program (7.2 M samples at
//! 250 Hz for 8): its wall time and the memory it took, streamed.
//!
//! `DEFLECT_BENCH_BUILTIN_ONLY=1` stops after the built-in job; `DEFLECT_BENCH_THREADS=1`
//! runs one thread count only.
//!
//! `cargo bench --bench job_throughput`

use std::time::Instant;

use deflect_core::machining::Program;
use deflect_core::machining::cutting::Tool;
use deflect_core::machining::job::{self, Job, JobSample, RunOptions, Setup};
use deflect_core::machining::tools::{ToolShape, ToolSpec, ToolTable};
use deflect_tests::{JOB_SEED as SEED, job_setup, kr300, programs, read_mm as read, repo_path};
use nalgebra::Vector2;

/// The KR 300 job of `deflect-sim job` over the stock `[min, max]` (mm), 0.5 mm cells.
fn setup(min: [f64; 2], max: [f64; 2]) -> Setup {
    job_setup(
        Vector2::new(min[0], min[1]) * 1e-3,
        Vector2::new(max[0], max[1]) * 1e-3,
        5.0e-4,
    )
}

fn ball_table() -> ToolTable {
    ToolTable::new(vec![ToolSpec {
        number: 1,
        tool: Tool::new(0.010, 2, 30f64.to_radians()).unwrap(),
        shape: ToolShape::Ball,
        length: 0.1,
        name: "10 mm ball".into(),
    }])
    .unwrap()
}

/// Peak resident memory of the process so far \[MB\] (Linux; 0 elsewhere).
fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

fn measure(name: &str, job: &Job, program: &Program, repeat: usize) {
    // `DEFLECT_BENCH_THREADS=1` runs one thread count only (for a profiler).
    let only: Option<usize> = std::env::var("DEFLECT_BENCH_THREADS")
        .ok()
        .and_then(|v| v.parse().ok());
    for threads in [1, 2] {
        if only.is_some_and(|n| n != threads) {
            continue;
        }
        let options = RunOptions {
            threads,
            ..RunOptions::default()
        };
        let mut best = f64::INFINITY;
        let (mut samples, mut cells, mut err) = (0usize, 0usize, 0.0f64);
        for _ in 0..repeat {
            let mut count = 0usize;
            let mut sink = |c: &[JobSample]| -> Result<(), std::convert::Infallible> {
                count += c.len();
                Ok(())
            };
            let t = Instant::now();
            let r = job::run_streaming(job, program, &SEED, &options, &mut sink).unwrap();
            best = best.min(t.elapsed().as_secs_f64());
            (samples, cells) = (count, r.cell_updates);
            err = r.path_error(true).max;
        }
        println!(
            "{name:<28} threads {threads}: {samples:>9} samples in {best:7.3} s = {:>9.0} \
             samples/s, {:>11.0} z-map cell updates/s; compensated path error max {:.2e} m; \
             peak memory {:.0} MB",
            samples as f64 / best,
            cells as f64 / best,
            err,
            peak_rss_mb()
        );
    }
}

fn main() {
    // `cargo bench` passes `--bench`; nothing to parse.
    let repeat: usize = std::env::var("DEFLECT_BENCH_REPEAT")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let robot = kr300();
    let builtin = read(&std::fs::read_to_string(repo_path("data/groove_and_pocket.nc")).unwrap());
    let job = Job::new(
        robot.model.clone(),
        &robot.joint_limits,
        setup([5.0, -15.0], [85.0, 45.0]),
    )
    .unwrap();
    measure("built-in job (16 mm flat)", &job, &builtin, repeat);
    if std::env::var("DEFLECT_BENCH_BUILTIN_ONLY").is_ok() {
        return;
    }

    let raster = read(&programs::raster(
        programs::waves(3.0, 1.5),
        (0.0, 100.0),
        (0.0, 100.0),
        0.5,
        1.0,
        600.0,
        12000.0,
    ));
    let job3d = Job::new(
        robot.model.clone(),
        &robot.joint_limits,
        setup([-6.0, -6.0], [106.0, 106.0]),
    )
    .unwrap()
    .with_tools(ball_table());
    measure("3-D raster (10 mm ball)", &job3d, &raster, repeat);

    if let Some(hours) = std::env::var("DEFLECT_BENCH_HOURS")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
    {
        // 10 mm/s: 36 m of raster per hour, 0.3 mm apart over a square.
        let side = (hours * 36_000.0 * 0.3).sqrt().ceil();
        let long = read(&programs::raster(
            programs::waves(3.0, 1.5),
            (0.0, side),
            (0.0, side),
            0.3,
            1.0,
            600.0,
            12000.0,
        ));
        let jobl = Job::new(
            robot.model.clone(),
            &robot.joint_limits,
            setup([-6.0, -6.0], [side + 6.0, side + 6.0]),
        )
        .unwrap()
        .with_tools(ball_table());
        measure(&format!("{hours} h raster (10 mm ball)"), &jobl, &long, 1);
    }
}
