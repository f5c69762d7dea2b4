//! `atlas`: bad regions and loads refused, a run's archive and summary.

use super::*;

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

#[test]
fn an_overload_is_beyond_the_model_not_out_of_reach() {
    // The reproducer: every point is in reach, the wrench turns the springs past
    // MAX_SPRING_ANGLE. The summary must say so, not "no point is reachable".
    let d = scratch("atlas-overload");
    let out = d.join("out");
    let o = sim(&[
        "atlas",
        "--wrench",
        "1e12,0,0,0,0,0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout.contains(
            "reachable points: 0 of 63; 63 in reach but beyond the model's validity (the \
             wrench turns a spring past MAX_SPRING_ANGLE)"
        ),
        "{}",
        o.stdout
    );
    assert!(
        o.stdout.contains("no point has a valid posture") && !o.stdout.contains("no point of"),
        "{}",
        o.stdout
    );
    // Out of reach stays out of reach: a region 10 m away.
    let far = d.join("far");
    let o = sim(&[
        "atlas",
        "--region",
        "10:11:2,0:1:2,0.2",
        "--out",
        far.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout.contains(
            "reachable points: 0 of 4; 4 out of reach\nno point of the region is reachable"
        ),
        "{}",
        o.stdout
    );
}
