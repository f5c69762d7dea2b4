//! `job --robot-program`, `job --spin` and `place`: their files and figures, and their
//! refusals.

use super::*;

fn slot(d: &Path) -> String {
    let program = d.join("slot.nc");
    std::fs::write(
        &program,
        "G0 X-10 Y0 Z5\nS13000 M3\nG1 Z-2 F1500\nX40\nG0 Z5\nM30\n",
    )
    .unwrap();
    program.to_str().unwrap().to_string()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn job_writes_the_robot_program_and_the_spin_search() {
    let d = scratch("job-program");
    let program = slot(&d);
    let out = d.join("run");
    let o = sim(&[
        "job",
        "--program",
        &program,
        "--stock",
        "0,-20,50,20",
        "--robot-program",
        "krl",
        "--spin",
        "optimize",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    for f in [
        "job_program.src",
        "job_program.dat",
        "job_program_joints.src",
        "job_program_joints.dat",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let src = std::fs::read_to_string(out.join("job_program.src")).unwrap();
    assert!(
        src.starts_with("&ACCESS RVP") && src.contains("\nLIN {E6POS: "),
        "{src}"
    );
    let joints = std::fs::read_to_string(out.join("job_program_joints.src")).unwrap();
    assert!(joints.contains("\nPTP {E6AXIS: A1 "));
    let s = json(&out.join("job_summary.json"));
    let spin = &s["spin"];
    let (opt, seed) = (
        spin["optimised"]["rms_m"].as_f64().unwrap(),
        spin["seed_constant"]["rms_m"].as_f64().unwrap(),
    );
    assert!(opt <= seed * (1.0 + 1e-9), "{opt} {seed}");
    assert!(
        o.stdout.contains("spin about the tool axis"),
        "{}",
        o.stdout
    );
    // The KR 300's controller is KUKA's: RAPID and URScript are refused before any work.
    refused(
        &d,
        &["job", "--robot-program", "rapid"],
        2,
        &["--robot-program rapid", "kuka's"],
    );
    refused(
        &d,
        &["job", "--robot-program", "urscript"],
        2,
        &["kuka's (KRL)"],
    );
    refused(
        &d,
        &["job", "--robot-program", "sps"],
        2,
        &["--robot-program"],
    );
    refused(&d, &["job", "--spin", "sideways"], 2, &["--spin"]);
    out_of_range(
        &d,
        &["job", "--spin-step", "0"],
        "--spin-step",
        "0",
        "[0.25, 90] degrees",
    );
    refused(
        &d,
        &["job", "--spin-rate", "1"],
        2,
        &["--spin-rate", "expected 2"],
    );
    refused(&d, &["job", "--spin-rate", "1,nan"], 2, &["--spin-rate"]);
}

#[test]
fn place_writes_the_best_placement_and_its_heat_map() {
    let d = scratch("place");
    let program = slot(&d);
    let out = d.join("run");
    let o = sim(&[
        "place",
        "--program",
        &program,
        "--stock",
        "0,-20,50,20",
        "--steps",
        "3,3,1,1",
        "--refine",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(out.join("place.png").exists());
    let s = json(&out.join("place_summary.json"));
    let best = s["best"]["rms_m"].as_f64().unwrap();
    assert_eq!(s["grid"].as_array().unwrap().len(), 9);
    let grid_best = s["grid"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|g| g["rms_m"].as_f64())
        .fold(f64::INFINITY, f64::min);
    assert!(best <= grid_best, "{best} {grid_best}");
    assert!(o.stdout.contains("best placement: x "), "{}", o.stdout);
    refused(&d, &["place", "--steps", "0,1,1,1"], 2, &["--steps"]);
    refused(
        &d,
        &["place", "--box", "3,2,0,1,0,1"],
        2,
        &["--box", "lower end first"],
    );
    refused(&d, &["place", "--yaw", "10,-10"], 2, &["--yaw"]);
    refused(
        &d,
        &["place", "--spin", "30"],
        2,
        &["--spin", "keep or optimize"],
    );
    // A box the arm reaches nowhere: a failure naming the box.
    let far = sim(&[
        "place",
        "--program",
        &program,
        "--stock",
        "0,-20,50,20",
        "--box",
        "5,6,5,6,0.9,0.9",
        "--steps",
        "2,2,1,1",
        "--out",
        d.join("far").to_str().unwrap(),
    ]);
    assert_eq!(far.code, 1, "{}", far.stderr);
    assert!(far.stderr.contains("outside reach"), "{}", far.stderr);
}
