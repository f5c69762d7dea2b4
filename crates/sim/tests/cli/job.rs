//! `job`: bad flags and files refused before any work, a run's files and summary.

use super::*;

#[test]
fn job_refuses_bad_flags_and_files_before_any_work() {
    let d = scratch("job-refusals");
    out_of_range(&d, &["job", "--cell", "0"], "--cell", "0", "[0.01, 10] mm");
    out_of_range(&d, &["job", "--flutes", "17"], "--flutes", "17", "[1, 16]");
    out_of_range(
        &d,
        &["job", "--rate", "1e6"],
        "--rate",
        "1e6",
        "[1, 10000] Hz",
    );
    refused(
        &d,
        &["job", "--placement", "1,2,3"],
        2,
        &["--placement", "expected 6"],
    );
    refused(
        &d,
        &["job", "--stock", "10,0,0,10"],
        2,
        &["--stock", "XMIN < XMAX"],
    );
    refused(&d, &["job", "--seed", "0,0"], 2, &["--seed", "expected 6"]);
    refused(
        &d,
        &["job", "--coefficients", "1,2,3,4,5,nan"],
        2,
        &["--coefficients", "not finite"],
    );
    // A malformed program names the file, the line and the column.
    let bad = d.join("bad.nc");
    std::fs::write(&bad, "G1 X10 F100\nG7 X5\n").unwrap();
    refused(
        &d,
        &["job", "--program", bad.to_str().unwrap()],
        1,
        &["--program", "bad.nc", "line 2, column 1"],
    );
    refused(
        &d,
        &["job", "--program", d.join("missing.nc").to_str().unwrap()],
        2,
        &["--program", "missing.nc"],
    );
    // A stock of more than 2^24 cells.
    refused(
        &d,
        &["job", "--stock", "0,0,10000,10000", "--cell", "0.01"],
        2,
        &["--stock", "MAX_CELLS"],
    );
}

#[test]
fn job_writes_the_compensated_program_samples_heat_map_and_summary() {
    let d = scratch("job-run");
    let out = d.join("out");
    let program = d.join("slot.nc");
    std::fs::write(
        &program,
        "G0 X-10 Y0 Z5\nS13000 M3\nG1 Z-2 F1500\nX40\nG0 Z5\nM30\n",
    )
    .unwrap();
    let o = sim(&[
        "job",
        "--program",
        program.to_str().unwrap(),
        "--stock",
        "0,-20,50,20",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(o.stdout.contains("job: "), "{}", o.stdout);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("job_summary.json")).unwrap())
            .unwrap();
    let un = summary["uncompensated"]["path_error_max_m"]
        .as_f64()
        .unwrap();
    let co = summary["compensated"]["path_error_max_m"].as_f64().unwrap();
    assert!(un > 1e-4 && co < 1e-7, "{un} {co}");
    // The slot line (file line 4) carries the force.
    let lines = summary["lines"].as_array().unwrap();
    assert!(
        lines
            .iter()
            .any(|l| l["line"] == 4 && l["max_force_n"].as_f64().unwrap() > 50.0)
    );
    let gcode = std::fs::read_to_string(out.join("job_compensated.nc")).unwrap();
    assert!(
        gcode.contains("(program line 4)") && gcode.contains("G1 X"),
        "{gcode}"
    );
    let csv = std::fs::read_to_string(out.join("job_samples.csv")).unwrap();
    assert!(csv.starts_with("time_s,line,x_m"));
    let png = std::fs::read(out.join("job_part.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}
