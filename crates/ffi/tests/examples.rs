//! The C and C++ examples, built with plain `cc`/`c++` against `libdeflect.a` by their
//! scripts, print exactly (bit for bit) what the same 2 kHz loop prints through the Rust API;
//! the C status-code program provokes every error code.

use std::path::{Path, PathBuf};
use std::process::Command;

use deflect_core::compliance_map::{OutOfGrid, QueryOptions};
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::io::map_csv;
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::motion::{Trajectory, paper_limits};
use deflect_core::units::{ForceUnit, LengthUnit};
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

/// The same loop through the Rust API: `parallel::correct_each` (the corrector's `Data`
/// keeps the previous tick's joints as seed), as `k t desired commanded joints`.
fn rust_rows() -> Vec<[f64; 8]> {
    let text = std::fs::read_to_string(repo().join("data/paksoy2025_compliance_oc.csv")).unwrap();
    let map = map_csv::from_str(&text, ForceUnit::Newton, LengthUnit::Millimetre)
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
    // The C corrector holds its own copy of the map, options included: so does this model.
    let model = Model::new(ParallelRobot2::paper(), map, parallel::PAPER_MASS).unwrap();
    // The IK seed starts at zero joints, as the C corrector's.
    let mut data = Data::new(&model);
    let times: Vec<f64> = traj.ticks(2000.0).unwrap().map(|s| s.t).collect();
    let mut rows = Vec::new();
    parallel::correct_each(&model, &mut data, &traj, 2000.0, |k, t| {
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
    })
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

/// The serial-arm loop of `examples/c/serial_kr300_dalembert.c` through the Rust API, with
/// the same arithmetic for the poses (row-major matrices, the end turned by cos/sin about z),
/// as `k t desired_xyz commanded_xyz q[0..6]`.
fn serial_rust_rows() -> Vec<Vec<f64>> {
    use deflect_core::SerialRobot;
    use deflect_core::dalembert::serial::{self, Payload};
    use deflect_core::motion::{Limits, PoseLimits, PoseTrajectory};
    use deflect_core::vjm::{self, pose_from_matrix};
    use nalgebra::{Matrix3, Matrix4, Vector3};

    let root = repo();
    let robot = SerialRobot::from_path(
        root.join("robots/kr300/kr300_r2500.urdf"),
        root.join("robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )
    .unwrap();
    let q0 = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
    let mut data = vjm::Data::new(&robot.model);
    let start = vjm::forward(&robot.model, &mut data, &q0)
        .unwrap()
        .to_homogeneous();
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let mut end: Matrix4<f64> = start;
    for col in 0..3 {
        let (x, y) = (start[(0, col)], start[(1, col)]);
        end[(0, col)] = c * x - s * y;
        end[(1, col)] = s * x + c * y;
    }
    end[(0, 3)] += 0.1;
    end[(1, 3)] += 0.3;
    end[(2, 3)] -= 0.1;
    let limits = PoseLimits {
        linear: Limits::new(2.0, 9.81, 200.0).unwrap(),
        angular: Limits::new(1.5, 8.0, 100.0).unwrap(),
    };
    let motion = PoseTrajectory::line(
        &pose_from_matrix(&start).unwrap(),
        &pose_from_matrix(&end).unwrap(),
        &limits,
    )
    .unwrap();
    let payload = Payload {
        mass: 150.0,
        com: Vector3::new(0.0, 0.0, 0.25),
        inertia: Matrix3::from_diagonal(&Vector3::new(4.0, 4.0, 2.5)),
    };
    let model = serial::Model::new(robot.model.clone(), payload)
        .unwrap()
        .with_joint_limits(&robot.joint_limits)
        .unwrap();
    let mut data = serial::Data::new(&model);
    data.set_seed(&q0);
    let n = motion.tick_count(2000.0).unwrap();
    (0..n)
        .map(|k| {
            let t = motion.tick_time(2000.0, k, n);
            let mut state = motion.sample(t).unwrap();
            // The C state carries the pose as a matrix, read back through the checked
            // conversion: so does this loop.
            state.pose = pose_from_matrix(&state.pose.to_homogeneous()).unwrap();
            let tick = serial::step(&model, &mut data, &state, None).unwrap();
            let (d, c) = (
                state.pose.translation.vector,
                tick.commanded.translation.vector,
            );
            let mut row = vec![k as f64, t, d.x, d.y, d.z, c.x, c.y, c.z];
            row.extend_from_slice(&tick.joints[..6]);
            row
        })
        .collect()
}

#[test]
fn c_serial_example_matches_the_rust_api_bit_for_bit() {
    let out = Command::new("bash")
        .arg(repo().join("examples/c/build_and_run.sh"))
        .env("DEFLECT_LIB_DIR", lib_dir())
        .env("DEFLECT_OUT_DIR", lib_dir().join("examples-c-serial"))
        .env("DEFLECT_EXAMPLE", "serial_kr300_dalembert")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "serial example failed:\n{stderr}");
    let got: Vec<Vec<f64>> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let want = serial_rust_rows();
    assert_eq!(got.len(), want.len(), "tick count");
    assert_eq!(want.len(), 952, "0.4755 s at 2 kHz");
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(g.len(), 14, "tick {k}: columns");
        for (i, (a, b)) in g.iter().zip(w).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "tick {k}, column {i}: {a} vs {b}");
        }
    }
    // A real correction: millimetres at 1 g with 150 kg on the KR 300.
    let largest = want
        .iter()
        .map(|r| ((r[5] - r[2]).powi(2) + (r[6] - r[3]).powi(2) + (r[7] - r[4]).powi(2)).sqrt())
        .fold(0.0, f64::max);
    assert!(
        largest > 1e-3 && largest < 1e-2,
        "largest correction {largest} m"
    );
}
