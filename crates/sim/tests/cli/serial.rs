//! `serial`: flags and files of any arm checked before any work.

use super::*;

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
