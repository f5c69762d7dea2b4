//! Input and output files: named in every error, checked before any work.

use super::*;

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
