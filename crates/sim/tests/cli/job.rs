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
    // A negative count names its flag (not "unexpected argument '-1'").
    for (cmd, flag) in [
        ("job", "--flutes"),
        ("milling", "--id-poses"),
        ("milling", "--seed"),
        ("milling", "--force"),
        ("delta", "--nodes"),
        ("contour", "--seed"),
    ] {
        let err = refused(&d, &[cmd, flag, "-1"], 2, &[flag]);
        assert!(!err.contains("unexpected argument"), "{err}");
    }
    // A yaw of 1e300 rad (degrees meant, or an overflow) and a NaN seed are usage errors.
    refused(
        &d,
        &["job", "--placement", "2.45,0.02,0.92,0,0,1e300"],
        2,
        &["--placement", "1e300", "2 pi"],
    );
    refused(
        &d,
        &["job", "--seed", "0,-0.9,1.4,0,-0.5,nan"],
        2,
        &["--seed", "NaN"],
    );
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
    out_of_range(
        &d,
        &["job", "--spindle-rpm", "0"],
        "--spindle-rpm",
        "0",
        "[1, 1000000] rpm",
    );
    out_of_range(
        &d,
        &["job", "--rapid-skim", "-1"],
        "--rapid-skim",
        "-1",
        "[0, 100] mm",
    );
    refused(
        &d,
        &["job", "--dialect", "mach3"],
        2,
        &["--dialect", "mach3"],
    );
    refused(
        &d,
        &["job", "--tools", d.join("missing.tbl").to_str().unwrap()],
        2,
        &["--tools", "missing.tbl"],
    );
    // A tool table without the program's tool, a malformed one.
    let two = d.join("two.nc");
    std::fs::write(
        &two,
        "T1 M6\nS9000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F300\nT2 M6\nM3\nG1 X5\n",
    )
    .unwrap();
    let tbl = d.join("one.tbl");
    std::fs::write(&tbl, "T1 P1 D6\n").unwrap();
    refused(
        &d,
        &[
            "job",
            "--program",
            two.to_str().unwrap(),
            "--tools",
            tbl.to_str().unwrap(),
        ],
        1,
        &["--tools", "one.tbl", "line 7 cuts with T2"],
    );
    std::fs::write(&tbl, "T1 P1\n").unwrap();
    refused(
        &d,
        &[
            "job",
            "--program",
            two.to_str().unwrap(),
            "--tools",
            tbl.to_str().unwrap(),
        ],
        1,
        &["--tools", "one.tbl", "line 1", "D"],
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
    // The slot line (file line 4) carries the largest force; it is the first of the ten.
    let lines = summary["top_lines"].as_array().unwrap();
    assert!(lines.len() <= 10);
    assert!(lines[0]["line"] == 4 && lines[0]["max_force_n"].as_f64().unwrap() > 50.0);
    assert!(summary["deviating_lines"].as_array().unwrap().is_empty());
    // One operation (the program has no comments): all its samples.
    let ops = summary["operations"].as_array().unwrap();
    assert_eq!(ops.len(), 1);
    assert_eq!(ops[0]["samples"], summary["samples"]);
    let gcode = std::fs::read_to_string(out.join("job_compensated.nc")).unwrap();
    assert!(
        gcode.contains("(program line 4)") && gcode.contains("G1 X"),
        "{gcode}"
    );
    // The samples: no CSV unless asked; the archive has every sample.
    assert!(!out.join("job_samples.csv").exists());
    let npz = std::fs::read(out.join("job_samples.npz")).unwrap();
    assert_eq!(&npz[..2], b"PK");
    // The archive's values: one time per sample, 4 ms apart; the largest force the summary's.
    let time = npy(&npz, "time");
    let samples = summary["samples"].as_u64().unwrap() as usize;
    assert_eq!(time.len(), samples);
    assert!(
        time.windows(2)
            .all(|w| (w[1] - w[0] - 0.004).abs() < 1e-9 || w[1] == time[samples - 1])
    );
    let force = npy(&npz, "force");
    assert_eq!(force.len(), 3 * samples);
    let largest = force
        .chunks(3)
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0f64, f64::max);
    let reported = summary["max_force_n"].as_f64().unwrap();
    assert!(
        (largest - reported).abs() <= 1e-9 * reported,
        "{largest} vs {reported}"
    );
    let mcap = std::fs::read(out.join("job.mcap")).unwrap();
    assert_eq!(&mcap[1..5], b"MCAP");
    let o = sim(&[
        "job",
        "--program",
        program.to_str().unwrap(),
        "--stock",
        "0,-20,50,20",
        "--samples-csv",
        "--threads",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    let csv = std::fs::read_to_string(out.join("job_samples.csv")).unwrap();
    assert!(csv.starts_with("time_s,line,x_m"));
    // One thread or two: the same figures.
    let again: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("job_summary.json")).unwrap())
            .unwrap();
    assert_eq!(again["compensated"], summary["compensated"]);
    assert_eq!(again["top_lines"], summary["top_lines"]);
    let rows = csv.lines().count() - 1;
    assert_eq!(Some(rows as u64), summary["samples"].as_u64());
    // The CSV's values are the archive's: time, position and force of every row (the CSV
    // prints them to 17 significant digits or so; 1e-12 relative).
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (ct, cx, cfx, cfz) = (col("time_s"), col("x_m"), col("fx_n"), col("fz_n"));
    let (time, position, force) = (npy(&npz, "time"), npy(&npz, "position"), npy(&npz, "force"));
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300);
    for (k, line) in csv.lines().skip(1).enumerate() {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect();
        assert!(
            close(v[ct], time[k]),
            "row {k}: time {} vs {}",
            v[ct],
            time[k]
        );
        assert!(close(v[cx], position[3 * k]), "row {k}: x");
        assert!(
            close(v[cfx], force[3 * k]) && close(v[cfz], force[3 * k + 2]),
            "row {k}: force"
        );
    }
    let png = std::fs::read(out.join("job_part.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn job_explains_a_programs_words_and_runs_two_tools_on_a_hand_started_spindle() {
    let d = scratch("job-tools");
    let program = d.join("two.nc");
    std::fs::write(
        &program,
        "%\nG21 G90 G17\nT1 M6\nG0 X-10 Y-8 Z5\nG1 Z-1 F600\nX40\nG0 Z5\nT2 M6 M8\n\
         G0 X-10 Y8\nG1 Z-1\nX40\nG0 Z5\nG41 D2\n%\n",
    )
    .unwrap();
    // The word report: every word, and where the reader refuses the program.
    let o = sim(&["job", "--explain", program.to_str().unwrap()]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout.contains("M8                     recorded"),
        "{}",
        o.stdout
    );
    assert!(
        o.stdout.contains("G41                    refused"),
        "{}",
        o.stdout
    );
    assert!(
        o.stdout.contains("refused: program line 13, column 1"),
        "{}",
        o.stdout
    );
    let text = std::fs::read_to_string(&program)
        .unwrap()
        .replace("G41 D2\n", "");
    std::fs::write(&program, text).unwrap();
    let tools = d.join("tools.toml");
    std::fs::write(
        &tools,
        "units = \"mm\"\n[[tool]]\nnumber = 1\ndiameter = 10\nflutes = 3\n\
         [[tool]]\nnumber = 2\ndiameter = 6\nflutes = 2\nshape = \"ball\"\n",
    )
    .unwrap();
    let out = d.join("out");
    let o = sim(&[
        "job",
        "--program",
        program.to_str().unwrap(),
        "--tools",
        tools.to_str().unwrap(),
        "--spindle-rpm",
        "12000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout
            .contains("T1 10.000 mm flat 3 flutes; T2 6.000 mm ball 2 flutes"),
        "{}",
        o.stdout
    );
    assert!(
        o.stdout.contains("spindle: hand-started at 12000 rpm"),
        "{}",
        o.stdout
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("job_summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["hand_spindle_rpm"].as_f64(), Some(12000.0));
    assert_eq!(summary["tools"][1]["shape"], "ball");
    // Both lines cut: the 10 mm slot (file line 6) and the 6 mm one (line 11); each tool
    // change starts an operation.
    let ops = summary["operations"].as_array().unwrap();
    assert_eq!(ops.len(), 2, "{ops:?}");
    assert_eq!(
        (ops[0]["tool"].as_u64(), ops[1]["tool"].as_u64()),
        (Some(1), Some(2))
    );
    let lines = summary["top_lines"].as_array().unwrap();
    for l in [6, 11] {
        assert!(
            lines
                .iter()
                .any(|x| x["line"] == l && x["max_force_n"].as_f64().unwrap() > 20.0),
            "{l}"
        );
    }
}

/// The float64 data of array `name` in an `.npz` archive (stored, little-endian, C order).
fn npy(npz: &[u8], name: &str) -> Vec<f64> {
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(npz)).unwrap();
    let mut file = zip.by_name(&format!("{name}.npy")).unwrap();
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut file, &mut bytes).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(
        header.contains("'descr': '<f8'") && header.contains("'fortran_order': False"),
        "{header}"
    );
    bytes[10 + header_len..]
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn job_runs_at_one_sample_per_second_and_with_sharp_limits() {
    // At 1 Hz the chord between samples crossed material the program never enters (exit 1,
    // "a rapid move runs 2.629 mm into the stock"); the stock now follows the path.
    let d = scratch("job-rates");
    for args in [
        &["job", "--rate", "1"][..],
        &["job", "--rate", "2"],
        &["job", "--rate", "10"],
        &["job", "--acceleration", "100", "--jerk", "10000"],
    ] {
        let out = d.join("out");
        let mut all = args.to_vec();
        all.extend(["--out", out.to_str().unwrap()]);
        let o = sim(&all);
        assert_eq!(o.code, 0, "{args:?}: {}", o.stderr);
    }
    // A 0.3 mm tool: the default cell goes below 0.1 mm to half its radius (the job refuses
    // coarser), and the job runs.
    let tiny = d.join("tiny.nc");
    std::fs::write(&tiny, "G0 X0 Y0 Z5\nS20000 M3\nG1 Z-0.1 F300\nX5\nG0 Z5\n").unwrap();
    let o = sim(&[
        "job",
        "--program",
        tiny.to_str().unwrap(),
        "--diameter",
        "0.3",
        "--flutes",
        "2",
        "--out",
        d.join("tiny").to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(o.stdout.contains("z-map cells of 0.075 mm"), "{}", o.stdout);
}

#[test]
fn job_reads_apt_by_its_extension_and_runs_a_tilted_axis_five_axis() {
    let d = scratch("job-apt");
    let flat = d.join("slot.apt");
    std::fs::write(
        &flat,
        "UNITS/MM\nSPINDL/13000,CLW\nRAPID\nGOTO/-10,0,5\nFEDRAT/MMPM,1500\nGOTO/-10,0,-2\n\
         GOTO/40,0,-2\nRAPID\nGOTO/40,0,5\nFINI\n",
    )
    .unwrap();
    let out = d.join("run");
    let o = sim(&[
        "job",
        "--program",
        flat.to_str().unwrap(),
        "--stock",
        "0,-20,50,20",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    // A swarf cut with an 8 mm flat cutter (CUTTER/) tilted 15 degrees: the five-axis pass.
    let tilted = d.join("tilted.apt");
    std::fs::write(
        &tilted,
        "UNITS/MM\nCUTTER/8\nSPINDL/12000,CLW\nRAPID\nGOTO/-12,-10,20,0,0,1\nRAPID\n\
         GOTO/-12,-10,5,0,-0.2588190,0.9659258\nFEDRAT/MMPM,1200\n\
         GOTO/-12,-10,-3,0,-0.2588190,0.9659258\nGOTO/40,-10,-3,0,-0.2588190,0.9659258\n\
         GOTO/40,-10,10,0,0,1\nFINI\n",
    )
    .unwrap();
    let five = d.join("five");
    let o = sim(&[
        "job",
        "--program",
        tilted.to_str().unwrap(),
        "--stock",
        "0,-20,30,20",
        "--cell",
        "1",
        "--stock-depth",
        "20",
        "--out",
        five.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(o.stdout.contains("five-axis job"), "{}", o.stdout);
    for f in [
        "part_uncompensated.ply",
        "part_compensated.ply",
        "part_view.png",
        "five_axis_samples.csv",
        "five_axis_summary.txt",
    ] {
        assert!(five.join(f).is_file(), "{f}");
    }
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(five.join("five_axis_summary.json")).unwrap(),
    )
    .unwrap();
    let mm = |p: &str| json.pointer(p).and_then(|v| v.as_f64()).unwrap();
    // The compensated tool holds the program to the IK's 1e-8 m, its part to a few times
    // that (tip and tilt together along the flank); the uncompensated ones are off by tenths.
    assert!(mm("/tool/compensated/max_position_mm") <= 1e-5, "{json}");
    assert!(mm("/tool/uncompensated/max_position_mm") > 0.01, "{json}");
    assert!(mm("/part/compensated/all/max_left_mm") <= 3e-5, "{json}");
    assert!(
        mm("/part/compensated/all/max_overcut_mm") >= -3e-5,
        "{json}"
    );
    assert!(mm("/part/uncompensated/all/rms_mm") > 0.005, "{json}");
    let ply = std::fs::read(five.join("part_compensated.ply")).unwrap();
    assert!(ply.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    // A spin turns the tool about the program's axis.
    let o = sim(&[
        "job",
        "--program",
        tilted.to_str().unwrap(),
        "--stock",
        "0,-20,30,20",
        "--cell",
        "1",
        "--spin",
        "10",
        "--out",
        five.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout
            .contains("turned about its axis by 10.0 .. 10.0 degrees"),
        "{}",
        o.stdout
    );
    // The testbed runs it in rapier: the force where the simulated tool is and as it is
    // tilted; the offline compensated joints leave less error than the rigid ones.
    let o = sim(&[
        "milling",
        "--program",
        tilted.to_str().unwrap(),
        "--stock",
        "-20,-20,50,10",
        "--out",
        five.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(five.join("milling_part_view.png").is_file());
    assert!(five.join("milling_part_offline.ply").is_file());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(five.join("milling_summary.json")).unwrap())
            .unwrap();
    let run = |k: usize, p: &str| json["runs"][k].pointer(p).and_then(|v| v.as_f64()).unwrap();
    assert!(run(0, "/rms_tip_mm") > 0.2, "{json}");
    assert!(
        run(1, "/rms_tip_mm") < 0.5 * run(0, "/rms_tip_mm"),
        "{json}"
    );
    assert!(run(1, "/part/rms_mm") < run(0, "/part/rms_mm"), "{json}");
    assert!(run(0, "/max_axis_mrad") > 0.1, "{json}");
    let bad = d.join("bad.apt");
    std::fs::write(&bad, "UNITS/MM\nSPLINE/1,2,3\n").unwrap();
    let o = sim(&[
        "job",
        "--program",
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert!(
        o.stderr.contains("line 2") && o.stderr.contains("SPLINE"),
        "{}",
        o.stderr
    );
}
