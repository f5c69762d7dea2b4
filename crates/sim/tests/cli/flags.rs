//! Numeric flags: each has a checked, documented range; usage errors exit 2.

use super::*;

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
fn milling_refuses_bad_programs_stocks_and_placements_before_any_work() {
    let d = scratch("milling-program-refusals");
    refused(
        &d,
        &["milling", "--stock", "1,2,3"],
        2,
        &["--stock", "expected 4"],
    );
    refused(
        &d,
        &["milling", "--stock", "10,0,0,10"],
        2,
        &["--stock", "XMIN < XMAX"],
    );
    refused(
        &d,
        &["milling", "--placement", "1,2,3,nan,0,0"],
        2,
        &["--placement", "expected 6 finite"],
    );
    refused(&d, &["milling", "--q0", "0,0"], 2, &["--q0", "expected 6"]);
    out_of_range(
        &d,
        &["milling", "--cell", "100"],
        "--cell",
        "100",
        "[0.01, 10] mm",
    );
    refused(&d, &["milling", "--jobs", "0"], 2, &["--jobs", "0"]);
    let bad = d.join("bad.nc");
    std::fs::write(&bad, "G1 X10 F100\nG2 X20 Y0 R1\n").unwrap();
    refused(
        &d,
        &["milling", "--program", bad.to_str().unwrap()],
        1,
        &["--program", "bad.nc", "line 2"],
    );
    refused(
        &d,
        &["milling", "--program", d.join("none.nc").to_str().unwrap()],
        2,
        &["--program", "none.nc"],
    );
}

#[test]
fn milling_checks_the_arm_tool_and_material_before_any_work() {
    let d = scratch("milling-arm-refusals");
    let urdf = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/kr300/kr300_r2500.urdf"
    );
    let stiff = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/kr300/kr300_r2500_stiffness.toml"
    );
    // A user's arm needs its stiffness, where the workpiece is and joints near it.
    refused(&d, &["milling", "--urdf", urdf], 2, &["--stiffness"]);
    refused(
        &d,
        &["milling", "--urdf", urdf, "--stiffness", stiff],
        2,
        &["--placement", "--q0"],
    );
    let arm = [
        "milling",
        "--urdf",
        urdf,
        "--stiffness",
        stiff,
        "--tip",
        "tcp",
        "--placement",
        "2.52,0.07,0.92,0,0,3.14159",
    ];
    let with = |extra: &[&'static str]| -> Vec<&str> { arm.iter().chain(extra).copied().collect() };
    refused(
        &d,
        &with(&["--q0", "0,-0.9,1.4,0,-0.5"]),
        2,
        &["--q0", "5 values given", "expected 6", "a1, a2"],
    );
    refused(
        &d,
        &with(&["--q0", "0,-0.9,1.4,0,-0.5,9"]),
        2,
        &["--q0", "joint 5", "outside its limits"],
    );
    refused(
        &d,
        &with(&["--q0", "0,-0.9,1.4,0,-0.5,0", "--program", "groove"]),
        2,
        &["--program groove", "--urdf"],
    );
    refused(
        &d,
        &with(&["--q0", "0,-0.9,1.4,0,-0.5,0", "--tip", "nowhere"]),
        2,
        &["--tip"],
    );
    refused(
        &d,
        &["milling", "--coefficients", "1,2,3"],
        2,
        &["--coefficients", "3 values", "expected 6"],
    );
    refused(
        &d,
        &["milling", "--material", "700,170,220,28,27,nan"],
        2,
        &["--coefficients", "not finite"],
    );
    refused(
        &d,
        &["milling", "--material", "-700,170,220,28,27,1"],
        2,
        &["--coefficients"],
    );
    out_of_range(
        &d,
        &["milling", "--diameter", "0"],
        "--diameter",
        "0",
        "[0.1, 200] mm",
    );
    out_of_range(
        &d,
        &["milling", "--flutes", "17"],
        "--flutes",
        "17",
        "[1, 16]",
    );
}

#[test]
fn comma_lists_may_start_with_a_minus_sign() {
    // clap reads "-0.1,0,..." as a flag unless the list takes hyphen values: a q0, a
    // placement or a wrench starting with a negative number must parse, and its checks run.
    let d = scratch("negative-lists");
    refused(
        &d,
        &["serial", "--q0", "-0.1,0,0"],
        2,
        &["--q0", "3 values given"],
    );
    refused(
        &d,
        &["milling", "--placement", "-2.5,0.07,nan,0,0,0"],
        2,
        &["--placement", "expected 6 finite"],
    );
    refused(
        &d,
        &["milling", "--stock", "-10,-10,-20,10"],
        2,
        &["--stock", "XMIN < XMAX"],
    );
    refused(
        &d,
        &["job", "--placement=-2.45,0.02,0.92,0,0"],
        2,
        &["--placement", "5 values"],
    );
}

#[test]
fn delta_flags_are_checked_before_any_work() {
    let d = scratch("delta-refusals");
    out_of_range(&d, &["delta", "--g", "20"], "--g", "20", "[1, 15] g");
    out_of_range(&d, &["delta", "--nodes", "1"], "--nodes", "1", "[2, 6]");
    out_of_range(
        &d,
        &["delta", "--payload-mass", "-1"],
        "--payload-mass",
        "-1",
        "[0, 10] kg",
    );
    out_of_range(
        &d,
        &["delta", "--test-force", "0"],
        "--test-force",
        "0",
        "[1, 500] N",
    );
    refused(&d, &["delta", "--jobs", "0"], 2, &["--jobs", "0"]);
}
