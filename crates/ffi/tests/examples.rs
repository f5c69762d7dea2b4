//! The C and C++ examples, built with plain `cc`/`c++` against `libdeflect.a` by their
//! scripts, print exactly (bit for bit) what the same 2 kHz loop prints through the Rust API;
//! the C status-code program provokes every error code.

use std::path::{Path, PathBuf};
use std::process::Command;

use deflect_core::compliance_map::{ComplianceMap, ForceUnit, LengthUnit, OutOfGrid, QueryOptions};
use deflect_core::dalembert::DalembertCorrector;
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Trajectory, paper_limits};
use nalgebra::Vector2;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// target/<profile>, where cargo put libdeflect.a before running this test.
fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let dir = exe.parent().unwrap().parent().unwrap().to_path_buf();
    assert!(
        dir.join("libdeflect.a").exists(),
        "no libdeflect.a in {}: run `cargo build -p deflect-ffi` first (scripts/test-all.sh does)",
        dir.display()
    );
    dir
}

fn run_script(script: &str, out_dir: &str) -> String {
    let out = Command::new("bash")
        .arg(repo().join(script))
        .env("DEFLECT_LIB_DIR", lib_dir())
        .env("DEFLECT_OUT_DIR", lib_dir().join(out_dir))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{script} failed:\n{stderr}");
    eprintln!("{stderr}");
    String::from_utf8(out.stdout).unwrap()
}

/// The same loop through the Rust API: `DalembertCorrector::correct_each`, the previous
/// tick's joints as seed, as `k t desired commanded joints`.
fn rust_rows() -> Vec<[f64; 8]> {
    let text = std::fs::read_to_string(repo().join("data/paksoy2025_compliance_oc.csv")).unwrap();
    let map = ComplianceMap::from_paper_csv(&text, ForceUnit::Newton, LengthUnit::Millimetre)
        .unwrap()
        .with_options(QueryOptions {
            out_of_grid: OutOfGrid::Clamp,
            ..QueryOptions::default()
        });
    let traj = Trajectory::line(
        Vector2::new(0.222132, -0.075),
        Vector2::new(0.222132, 0.075),
        &paper_limits(5).unwrap(),
    )
    .unwrap();
    let corr = DalembertCorrector::new(DalembertCorrector::PAPER_MASS).unwrap();
    let times: Vec<f64> = traj.ticks(2000.0).unwrap().map(|s| s.t).collect();
    let mut rows = Vec::new();
    corr.correct_each(
        &ParallelRobot2::paper(),
        &map.view(),
        &traj,
        2000.0,
        &Vector2::zeros(),
        |k, t| {
            rows.push([
                k as f64,
                times[k],
                t.desired.x,
                t.desired.y,
                t.commanded.x,
                t.commanded.y,
                t.joints.x,
                t.joints.y,
            ])
        },
    )
    .unwrap();
    rows
}

fn parse(output: &str) -> Vec<[f64; 8]> {
    output
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            v.try_into().unwrap()
        })
        .collect()
}

fn assert_bitwise_equal(what: &str, got: &[[f64; 8]], want: &[[f64; 8]]) {
    assert_eq!(got.len(), want.len(), "{what}: tick count");
    assert_eq!(
        want.len(),
        749,
        "the 5 g y-line lasts 373.6 ms: 749 ticks at 2 kHz"
    );
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        for (i, (a, b)) in g.iter().zip(w).enumerate() {
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "{what}: tick {k}, column {i}: {a} vs {b}"
            );
        }
    }
    // The correction is real: the command differs from the path by up to tens of um.
    let largest = want
        .iter()
        .map(|r| (r[4] - r[2]).hypot(r[5] - r[3]))
        .fold(0.0, f64::max);
    assert!(
        largest > 1e-5 && largest < 1e-3,
        "largest correction {largest} m"
    );
}

#[test]
fn c_example_matches_the_rust_api_bit_for_bit() {
    // The script also builds and runs examples/c/status_codes.c, which exits non-zero unless
    // every error code comes back as documented.
    let out = run_script("examples/c/build_and_run.sh", "examples-c");
    assert_bitwise_equal("C", &parse(&out), &rust_rows());
}

#[test]
fn cpp_example_matches_the_rust_api_bit_for_bit() {
    let out = run_script("examples/cpp/build_and_run.sh", "examples-cpp");
    assert_bitwise_equal("C++", &parse(&out), &rust_rows());
}
