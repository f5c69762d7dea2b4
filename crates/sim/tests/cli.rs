//! The command line of `deflect-sim` (the built binary): every refused input exits with code 2
//! (usage) or 1 (failure) and one `error: ...` line on stderr naming the flag or file, before
//! any work (the output directory is not even created) and at once; never a panic. Each test
//! is named for the reproducer it guards. One quick successful `fit` is the only run.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_deflect-sim");

/// A refusal takes no work: well under a second; the bound leaves room for a loaded machine.
const PROMPT: Duration = Duration::from_secs(5);

/// A fresh scratch directory for one test, removed afterwards.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("deflect-sim-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

struct Outcome {
    code: i32,
    stdout: String,
    stderr: String,
    elapsed: Duration,
}

/// Runs the binary with `args` (progress bars off).
fn sim(args: &[&str]) -> Outcome {
    sim_with(args, Stdio::piped())
}

/// [`sim`] with stdout going to `stdout`.
fn sim_with(args: &[&str], stdout: Stdio) -> Outcome {
    let t = Instant::now();
    let o = Command::new(BIN)
        .args(args)
        .env("CI", "1")
        .env_remove("RUST_BACKTRACE")
        .stdout(stdout)
        .output()
        .unwrap();
    Outcome {
        code: o.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        elapsed: t.elapsed(),
    }
}

/// Runs `args` with `--out <dir>/out` and checks the refusal: exit `code`, nothing on stdout,
/// exactly one stderr line `error: ...` containing every `needle`, promptly, the output
/// directory not created. Returns the line.
fn refused(dir: &Path, args: &[&str], code: i32, needles: &[&str]) -> String {
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    let mut all = args.to_vec();
    if !args.contains(&"--out") {
        all.extend(["--out", out_s]);
    }
    let o = sim(&all);
    let lines: Vec<&str> = o.stderr.lines().collect();
    assert_eq!(o.code, code, "{args:?}: exit code; stderr {:?}", o.stderr);
    assert_eq!(lines.len(), 1, "{args:?}: one stderr line: {:?}", o.stderr);
    let line = lines[0];
    assert!(line.starts_with("error: "), "{args:?}: {line}");
    assert!(!line.contains("panicked"), "{args:?}: {line}");
    for n in needles {
        assert!(line.contains(n), "{args:?}: {n:?} not in {line:?}");
    }
    assert!(
        o.stdout.is_empty(),
        "{args:?}: no work, no output: {:?}",
        o.stdout
    );
    assert!(
        o.elapsed < PROMPT,
        "{args:?}: refused after {:?}",
        o.elapsed
    );
    assert!(!out.exists(), "{args:?}: the output directory was created");
    line.to_string()
}

/// A usage refusal (exit 2) of `flag value`, naming both and the `range`.
fn out_of_range(dir: &Path, args: &[&str], flag: &str, value: &str, range: &str) {
    let line = refused(dir, args, 2, &[flag, value, range]);
    assert!(
        line.contains(&format!("{flag} {value} is out of range: allowed {range}")),
        "{line}"
    );
}

#[test]
fn milling_cut_1e9_is_refused_instead_of_a_failed_86_tb_allocation() {
    let d = scratch("cut1e9");
    out_of_range(
        &d,
        &["milling", "--cut", "1e9"],
        "--cut",
        "1e9",
        "[0.01, 5] s",
    );
}

#[test]
fn milling_cut_3000_is_refused_instead_of_running_for_minutes() {
    let d = scratch("cut3000");
    out_of_range(
        &d,
        &["milling", "--cut", "3000"],
        "--cut",
        "3000",
        "[0.01, 5] s",
    );
}

#[test]
fn every_length_count_and_level_flag_has_a_checked_range() {
    let d = scratch("ranges");
    // (subcommand, flag, range, values outside it as the error shows them)
    let cases: &[(&str, &str, &str, &[&str])] = &[
        (
            "milling",
            "--feed",
            "[0.1, 50] mm/s",
            &["0.09", "51", "NaN", "inf"],
        ),
        ("milling", "--force", "[0, 2000] N", &["-1", "2001", "1e30"]),
        ("milling", "--cut", "[0.01, 5] s", &["0.001", "5.5", "-inf"]),
        ("milling", "--rise-ms", "[0.1, 300] ms", &["0", "301"]),
        (
            "milling",
            "--cycle-ms",
            "[0.5, 20] ms",
            &["0", "0.25", "20.5", "1e9"],
        ),
        ("milling", "--lead-ms", "[0, 500] ms", &["-1", "501"]),
        (
            "milling",
            "--estimate-error",
            "[-1, 1]",
            &["-1.5", "2", "NaN"],
        ),
        ("contour", "--step-mm", "[0.2, 20] mm", &["0", "0.1", "21"]),
        (
            "contour",
            "--target-force",
            "(1.5, 30) N",
            &["1.5", "30", "100"],
        ),
        ("contour", "--noise", "[0, 5] N", &["-0.1", "6", "inf"]),
        (
            "contour",
            "--jobs",
            "[1, 64]",
            &["65", "18446744073709551615"],
        ),
        ("reproduce", "--mass", "[0, 50] kg", &["-1", "51", "NaN"]),
        ("reproduce", "--g", "[1, 5] g", &["0", "6", "255"]),
        ("reproduce", "--fixed-point", "[0, 50]", &["51", "1000000"]),
        ("reproduce", "--jobs", "[1, 64]", &["65"]),
        ("run", "--g", "[1, 5] g", &["0", "7"]),
        ("run", "--mass", "[0, 50] kg", &["-0.5", "1e6"]),
    ];
    for (sub, flag, range, values) in cases {
        for v in *values {
            let arg = format!("{flag}={v}");
            out_of_range(&d, &[sub, &arg], flag, v, range);
        }
    }
}

#[test]
fn jobs_0_is_refused_not_silently_one() {
    let d = scratch("jobs0");
    for sub in ["reproduce", "contour"] {
        out_of_range(&d, &[sub, "--jobs", "0"], "--jobs", "0", "[1, 64]");
    }
    // Without a subcommand, `reproduce` runs with its defaults (in range): nothing to refuse.
}

#[test]
fn run_g_6_is_refused_before_the_static_tests_and_the_fit() {
    let d = scratch("g6");
    // Arguments are checked before the input files and the output directory.
    out_of_range(
        &d,
        &["run", "--g", "6", "--map", "/nonexistent/map.json"],
        "--g",
        "6",
        "[1, 5] g",
    );
}

#[test]
fn reproduce_levels_must_be_distinct() {
    let d = scratch("levels");
    refused(
        &d,
        &["reproduce", "--g", "1,2,2"],
        2,
        &["--g 2 is given twice", "[1, 5] g"],
    );
}

#[test]
fn milling_cycle_must_be_a_whole_number_of_physics_steps() {
    let d = scratch("cycle");
    // 0.7 ms used to run with 0.5 ms cycles while the compensator assumed 0.7 ms.
    refused(
        &d,
        &["milling", "--cycle-ms", "0.7"],
        2,
        &[
            "--cycle-ms 0.7",
            "multiple of the 0.5 ms physics step",
            "[0.5, 20] ms",
        ],
    );
}

#[test]
fn negative_estimate_error_is_a_value_not_a_flag() {
    let d = scratch("negative");
    out_of_range(
        &d,
        &["milling", "--estimate-error", "-2"],
        "--estimate-error",
        "-2",
        "[-1, 1]",
    );
}

#[test]
fn clap_usage_errors_exit_2() {
    for args in [
        &["milling", "--cut", "abc"][..],
        &["contour", "--jobs", "-1"],
        &["reproduce", "--g", ""],
        &["run", "--no-such-flag"],
        &["no-such-command"],
    ] {
        let o = sim(args);
        assert_eq!(o.code, 2, "{args:?}: {}", o.stderr);
        assert!(o.stderr.starts_with("error: "), "{args:?}: {}", o.stderr);
        assert!(o.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn every_range_is_in_the_help() {
    let cases: &[(&str, &[&str])] = &[
        (
            "milling",
            &[
                "[0.1, 50] mm/s",
                "[0, 2000] N",
                "[0.01, 5] s",
                "[0.1, 300] ms",
                "[0.5, 20] ms",
                "[0, 500] ms",
                "[-1, 1]",
            ],
        ),
        (
            "contour",
            &["[0.2, 20] mm", "(1.5, 30) N", "[0, 5] N", "[1, 64]"],
        ),
        (
            "reproduce",
            &["[0, 50] kg", "[1, 5] g", "[0, 50]", "[1, 64]"],
        ),
        ("run", &["[1, 5] g", "[0, 50] kg"]),
    ];
    for (sub, ranges) in cases {
        let o = sim(&[sub, "--help"]);
        assert_eq!(o.code, 0);
        for r in *ranges {
            assert!(
                o.stdout.contains(&format!("Range: {r}.")),
                "{sub} --help lacks {r}: {}",
                o.stdout
            );
        }
    }
}

#[test]
fn fit_input_nonexistent_names_the_file() {
    let d = scratch("nofile");
    let line = refused(
        &d,
        &["fit", "--input", "/nonexistent.csv"],
        2,
        &[
            "--input /nonexistent.csv",
            "static-test CSV",
            "No such file",
        ],
    );
    assert_ne!(line, "error: No such file or directory (os error 2)");
}

#[test]
fn fit_input_that_is_not_a_regular_file_is_refused_without_reading() {
    let d = scratch("notfile");
    let dir = d.to_str().unwrap();
    // A directory, an endless device, an empty device: never read (a FIFO could block).
    for p in [dir, "/dev/zero", "/dev/null"] {
        refused(
            &d,
            &["fit", "--input", p],
            2,
            &[
                &format!("--input {p}"),
                "not a regular file",
                "static-test CSV",
            ],
        );
    }
}

#[test]
fn fit_input_with_bad_content_names_the_file() {
    let d = scratch("badcsv");
    let cases = [
        ("unknown.csv", "a,b\n1,2\n".to_string(), "unknown column"),
        ("empty.csv", String::new(), "missing column"),
        (
            "number.csv",
            "x,y,force_axis,force,dx,dy\n1,2,x,abc,0,0\n".to_string(),
            "not a valid number",
        ),
    ];
    for (name, text, why) in cases {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        let ps = p.to_str().unwrap();
        refused(
            &d,
            &["fit", "--input", ps],
            1,
            &[&format!("--input {ps}"), "not a valid static-test CSV", why],
        );
    }
    // Over the loaders' 16 MiB budget: refused, not read whole.
    let big = d.join("big.csv");
    std::fs::write(&big, vec![b'x'; (16 << 20) + 10]).unwrap();
    let bs = big.to_str().unwrap();
    refused(
        &d,
        &["fit", "--input", bs],
        1,
        &[&format!("--input {bs}"), "at most 16777216"],
    );
}

#[test]
fn run_map_errors_name_the_file_even_with_correction_off() {
    let d = scratch("badmap");
    refused(
        &d,
        &["run", "--map", "/nonexistent/map.json"],
        2,
        &[
            "--map /nonexistent/map.json",
            "compliance map JSON",
            "No such file",
        ],
    );
    let cases = [
        (
            "bad.json",
            b"{\"format_version\": 1}".to_vec(),
            "not a valid",
        ),
        ("text.json", b"x,y\n1,2\n".to_vec(), "not a valid"),
        ("binary.json", vec![0xff, 0xfe, 0x00], "static-test CSV"),
    ];
    for (name, bytes, why) in cases {
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        let ps = p.to_str().unwrap();
        // What the file looked like: a JSON map starts with `{`, anything else is read as the
        // static-test CSV; the error says which was expected.
        let kind = if name == "bad.json" {
            "compliance map JSON"
        } else {
            "static-test CSV"
        };
        for correction in ["on", "off"] {
            refused(
                &d,
                &["run", "--map", ps, "--correction", correction],
                1,
                &[&format!("--map {ps}"), kind, why],
            );
        }
    }
}

#[test]
fn out_that_cannot_be_a_directory_is_refused_for_every_command() {
    let d = scratch("badout");
    let file = d.join("a_file");
    std::fs::write(&file, "not a directory").unwrap();
    let under = file.join("sub");
    let csv = d.join("in.csv");
    std::fs::write(&csv, "x,y,force_axis,force,dx,dy\n").unwrap();
    let commands: &[&[&str]] = &[
        &[],
        &["reproduce"],
        &["static-test"],
        &["fit"],
        &["run"],
        &["milling"],
        &["contour"],
        &["serial"],
    ];
    for (out, why) in [
        (&file, "exists and is not a directory"),
        (&under, "cannot create the output directory"),
    ] {
        let os = out.to_str().unwrap();
        for cmd in commands {
            let mut args = cmd.to_vec();
            args.extend(["--out", os]);
            refused(&d, &args, 2, &[&format!("--out {os}"), why]);
        }
    }
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        "not a directory",
        "the file is left alone"
    );
}

#[test]
fn input_is_checked_before_the_output_directory() {
    let d = scratch("order");
    let file = d.join("a_file");
    std::fs::write(&file, "").unwrap();
    refused(
        &d,
        &[
            "fit",
            "--input",
            "/nonexistent.csv",
            "--out",
            file.to_str().unwrap(),
        ],
        2,
        &["--input /nonexistent.csv"],
    );
}

/// A small static-test table on a 3 x 5 grid (mm, N), displacement linear in the force.
fn static_table() -> String {
    let mut s = String::from("x,y,force_axis,force,dx,dy\n");
    for i in 0..3 {
        for j in 0..5 {
            let (x, y) = (122.132 + 50.0 * f64::from(i), -75.0 + 37.5 * f64::from(j));
            for axis in ["x", "y"] {
                for f in [49.05, 98.1, 147.15] {
                    let c = 1e-3 * (1.0 + 0.1 * f64::from(i) + 0.05 * f64::from(j));
                    let (dx, dy) = if axis == "x" {
                        (c * f, 0.1 * c * f)
                    } else {
                        (0.1 * c * f, 2.0 * c * f)
                    };
                    s.push_str(&format!("{x},{y},{axis},{f},{dx:e},{dy:e}\n"));
                }
            }
        }
    }
    s
}

#[test]
fn fit_accepts_a_valid_table_and_leaves_no_probe_behind() {
    let d = scratch("fitok");
    let csv = d.join("static.csv");
    std::fs::write(&csv, static_table()).unwrap();
    let out = d.join("fresh/out");
    let o = sim(&[
        "fit",
        "--mechanism",
        "oc",
        "--input",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(o.stdout.contains("map: 3 x 5 nodes"), "{}", o.stdout);
    let files: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(files, ["compliance_map_oc.json"]);
}

#[test]
fn a_failing_stdout_is_an_error_not_a_panic() {
    // `deflect-sim ... | head -1` or a full disk: println! used to panic.
    let d = scratch("stdout");
    let csv = d.join("static.csv");
    std::fs::write(&csv, static_table()).unwrap();
    let out = d.join("out");
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let o = sim_with(
        &[
            "fit",
            "--input",
            csv.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        Stdio::from(full),
    );
    assert_eq!(o.code, 1, "{}", o.stderr);
    let lines: Vec<&str> = o.stderr.lines().collect();
    assert_eq!(
        lines,
        ["error: cannot write to standard output: No space left on device (os error 28)"]
    );
}

#[test]
fn serial_flags_are_checked_before_any_work() {
    let d = scratch("serialflags");
    out_of_range(&d, &["serial", "--g", "9"], "--g", "9", "[0.05, 5] g");
    out_of_range(
        &d,
        &["serial", "--payload-mass", "-1"],
        "--payload-mass",
        "-1",
        "[0, 2000] kg",
    );
    out_of_range(
        &d,
        &["serial", "--ramp", "0"],
        "--ramp",
        "0",
        "[0.005, 1] s",
    );
    out_of_range(&d, &["serial", "--jobs", "0"], "--jobs", "0", "[1, 64]");
    refused(
        &d,
        &["serial", "--q0", "0,0,0,0,0,nan"],
        2,
        &["--q0", "joint 5 is NaN"],
    );
    refused(
        &d,
        &["serial", "--q0", "0.1,0.2"],
        2,
        &["--q0: 2 values given; expected 6", "a1"],
    );
    refused(
        &d,
        &["serial", "--q0", "0,-0.9,1.4,0,1.07,9"],
        2,
        &["--q0: joint 5 (a6) is 9 rad: outside its limits"],
    );
}

#[test]
fn serial_files_are_named_in_their_errors() {
    let d = scratch("serialfiles");
    let stiff = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/kr300/kr300_r2500_stiffness.toml"
    );
    let urdf = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/kr300/kr300_r2500.urdf"
    );
    // A URDF without a stiffness file is a clap usage error.
    let o = sim(&[
        "serial",
        "--urdf",
        urdf,
        "--out",
        d.join("o").to_str().unwrap(),
    ]);
    assert_eq!(o.code, 2, "{}", o.stderr);
    assert!(o.stderr.contains("--stiffness"), "{}", o.stderr);
    refused(
        &d,
        &[
            "serial",
            "--urdf",
            "/nonexistent.urdf",
            "--stiffness",
            stiff,
        ],
        2,
        &["--urdf /nonexistent.urdf", "robot URDF", "No such file"],
    );
    let bad_urdf = d.join("bad.urdf");
    std::fs::write(&bad_urdf, "<robot name=\"r\"><link name=\"a\"></robot>").unwrap();
    let bu = bad_urdf.to_str().unwrap();
    refused(
        &d,
        &["serial", "--urdf", bu, "--stiffness", stiff],
        1,
        &[&format!("--urdf {bu}: not a valid robot URDF")],
    );
    let bad_stiff = d.join("bad.toml");
    std::fs::write(
        &bad_stiff,
        "[[virtual_joint]]\njoint = \"no_such_joint\"\nk = [1e5, 1e6, 1e6]\n",
    )
    .unwrap();
    let bs = bad_stiff.to_str().unwrap();
    refused(
        &d,
        &["serial", "--urdf", urdf, "--stiffness", bs, "--tip", "tcp"],
        1,
        &[&format!("--stiffness {bs}"), "no_such_joint"],
    );
    let neg = d.join("neg.toml");
    std::fs::write(
        &neg,
        "[[virtual_joint]]\njoint = \"a1\"\nk = [-1e5, 1e6, 1e6]\n",
    )
    .unwrap();
    let ns = neg.to_str().unwrap();
    refused(
        &d,
        &["serial", "--stiffness", ns],
        1,
        &[&format!("--stiffness {ns}"), "stiffness about x is -100000"],
    );
    refused(
        &d,
        &[
            "serial",
            "--urdf",
            urdf,
            "--stiffness",
            stiff,
            "--tip",
            "nowhere",
        ],
        1,
        &["nowhere"],
    );
}

#[test]
fn atlas_refuses_bad_regions_axes_wrenches_and_seeds_before_any_work() {
    let d = scratch("atlas-refusals");
    for (region, why) in [
        ("1:2:3,0:1:3", "not three comma-separated parts"),
        ("1:2,0:1:3,0.2", "is not FROM:TO:N"),
        ("1:2:0,0:1:3,0.2", "0 points on an axis"),
        ("1:2:101,0:1:3,0.2", "101 points on an axis"),
        ("1:x:3,0:1:3,0.2", "'x' is not a number"),
        ("1:2:3,0:1:3,5000", "not a coordinate within 1000 m"),
    ] {
        refused(&d, &["atlas", "--region", region], 2, &["--region", why]);
    }
    out_of_range(
        &d,
        &["atlas", "--angle-step", "0"],
        "--angle-step",
        "0",
        "[0.1, 90] deg",
    );
    refused(
        &d,
        &["atlas", "--tool-axis", "0,0,0"],
        2,
        &["--tool-axis", "non-zero"],
    );
    refused(
        &d,
        &["atlas", "--wrench", "1,2"],
        2,
        &["--wrench", "expected 6"],
    );
    refused(
        &d,
        &["atlas", "--seed", "0,0,0"],
        2,
        &["--seed", "expected 6"],
    );
    refused(&d, &["atlas", "--jobs", "0"], 2, &["--jobs", "0"]);
}

#[test]
fn atlas_writes_a_compressed_archive_and_a_heat_map() {
    let d = scratch("atlas-run");
    let out = d.join("out");
    let o = sim(&[
        "atlas",
        "--region",
        "1.6:1.8:2,-0.1:0.1:2,0.2",
        "--angle-step",
        "30",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout.contains("reachable points: 4 of 4"),
        "{}",
        o.stdout
    );
    assert!(o.stdout.contains("best placement: x = "), "{}", o.stdout);
    let npz = std::fs::read(out.join("atlas.npz")).unwrap();
    assert_eq!(&npz[..2], b"PK", "a zip archive");
    let png = std::fs::read(out.join("atlas.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}
