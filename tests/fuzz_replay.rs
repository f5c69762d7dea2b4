//! Replays every committed fuzz input, the seed corpora `fuzz/corpus/<target>/` and the crash
//! reproducers `fuzz/regressions/<target>/`, through the harnesses the fuzz targets run
//! (`deflect_tests::fuzz`), on stable Rust. A missing or empty directory fails: a replay of
//! nothing is not a test. `scripts/fuzz.sh` fuzzes (nightly) and adds to both directories.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use deflect_tests::fuzz::{self, TARGETS};

/// Largest replay time per directory: the committed corpora are small; a slow input is a
/// finding of its own (the fuzzer's inputs are at most a few kilobytes).
const BUDGET: Duration = Duration::from_secs(5);

/// The files of `fuzz/<kind>/<target>/`, sorted; panics when there are none.
fn inputs(kind: &str, target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz")
        .join(kind)
        .join(target);
    let entries = match std::fs::read_dir(&dir) {
        Ok(e) => e,
        Err(e) => panic!("{}: {e} (every fuzz target needs it)", dir.display()),
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(
        !files.is_empty(),
        "{} holds no input: a replay of nothing is not a test",
        dir.display()
    );
    files
}

/// Replays `fuzz/<kind>/*/`; returns, per target, how many inputs loaded a model.
fn replay(kind: &str) -> Vec<(&'static str, usize)> {
    let mut loaded = Vec::new();
    for (target, harness) in TARGETS {
        let files = inputs(kind, target);
        let t0 = Instant::now();
        let mut n_loaded = 0;
        for path in &files {
            let data = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            // The harness panics (and names the invariant) if the input breaks one; say which
            // file it was first.
            match std::panic::catch_unwind(|| harness(&data)) {
                Ok(model) => n_loaded += usize::from(model),
                Err(panic) => {
                    eprintln!("fuzz input {} failed", path.display());
                    std::panic::resume_unwind(panic);
                }
            }
        }
        let elapsed = t0.elapsed();
        println!(
            "{kind}/{target}: {} inputs ({n_loaded} load a model) in {:.0} ms",
            files.len(),
            elapsed.as_secs_f64() * 1e3
        );
        assert!(
            elapsed < BUDGET,
            "{kind}/{target}: {} inputs took {elapsed:?} (budget {BUDGET:?})",
            files.len()
        );
        loaded.push((target, n_loaded));
    }
    loaded
}

#[test]
fn corpus_replays_clean() {
    // A seed corpus none of whose inputs loads only exercises the parser's error paths.
    for (target, n_loaded) in replay("corpus") {
        assert!(
            n_loaded > 0,
            "no input of fuzz/corpus/{target}/ loads a model"
        );
    }
}

#[test]
fn regressions_replay_clean() {
    replay("regressions");
}

#[test]
fn every_input_directory_is_a_target() {
    // A directory of no target would never be replayed.
    for kind in ["corpus", "regressions"] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fuzz")
            .join(kind);
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for entry in entries.filter_map(Result::ok) {
            let name = entry.file_name().to_string_lossy().into_owned();
            if entry.path().is_dir() {
                assert!(
                    TARGETS.iter().any(|(t, _)| *t == name),
                    "fuzz/{kind}/{name}/ is no fuzz target's directory"
                );
            }
        }
    }
}

#[test]
fn committed_corpus_stays_small() {
    // scripts/fuzz.sh minimises the corpus it commits; a huge generated input or an
    // unminimised corpus must not land.
    const MAX_FILES: usize = 250;
    const MAX_BYTES: u64 = 2 << 20;
    let (mut files, mut bytes) = (0, 0);
    for (target, _) in TARGETS {
        for path in inputs("corpus", target) {
            files += 1;
            bytes += std::fs::metadata(&path).map_or(0, |m| m.len());
        }
    }
    assert!(
        files <= MAX_FILES && bytes <= MAX_BYTES,
        "fuzz/corpus holds {files} files, {bytes} bytes (at most {MAX_FILES}, {MAX_BYTES}): \
         minimise it (scripts/fuzz.sh does)"
    );
}

#[test]
fn every_target_has_a_fuzz_binary() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/fuzz_targets");
    for (target, _) in TARGETS {
        let path = dir.join(format!("{target}.rs"));
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            text.contains(&format!("deflect_tests::fuzz::{target}(")),
            "{} must call the shared harness deflect_tests::fuzz::{target}",
            path.display()
        );
    }
}

#[test]
fn urdf_stiffness_inputs_split_at_the_first_nul() {
    let joined = fuzz::join_urdf_stiffness(fuzz::KR300_URDF, fuzz::KR300_STIFFNESS);
    let (u, s) = fuzz::split_urdf_stiffness(&joined);
    assert_eq!(u, fuzz::KR300_URDF.as_bytes());
    assert_eq!(s, fuzz::KR300_STIFFNESS.as_bytes());
    assert!(fuzz::urdf_stiffness(&joined), "the shipped robot loads");
    assert_eq!(
        fuzz::split_urdf_stiffness(b"<robot/>"),
        (&b"<robot/>"[..], &b""[..])
    );
}

/// Writes the seed inputs of every target into `fuzz/corpus/<target>/seed_*` (run by hand:
/// `cargo test -p deflect-tests --test fuzz_replay -- --ignored write_seed_corpus`). The
/// seeds come from the shipped robot and tables and from deflect's own writers.
#[test]
#[ignore = "writes fuzz/corpus/; run by hand to regenerate the seeds"]
fn write_seed_corpus() {
    use deflect_core::io::{map_csv, map_json};
    use deflect_core::units::{ForceUnit, LengthUnit};

    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let write = |target: &str, name: &str, data: &[u8]| {
        let dir = root.join("fuzz/corpus").join(target);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(format!("seed_{name}")), data).unwrap();
    };
    let read = |rel: &str| std::fs::read_to_string(root.join(rel)).unwrap();

    // drive_toml: one [[joint]] per KR 300 joint; alone and in the combined stiffness file.
    let drive = "# Drive train of the KR 300 R2500 (stiffness N m/rad, backlash rad)\n\
                 [[joint]]\nname = \"a1\"\nstiffness = 5.0e6\nbacklash = 1.0e-4\n\n\
                 [[joint]]\nname = \"a2\"\nstiffness = 6.5e6\nbacklash = 1.0e-4\n\n\
                 [[joint]]\nname = \"a3\"\nstiffness = 4.0e6\n\n\
                 [[joint]]\nname = \"a4\"\nstiffness = 1.2e6\nbacklash = 2.0e-4\n\n\
                 [[joint]]\nname = \"a5\"\nstiffness = 9.0e5\nbacklash = 0.0\n\n\
                 [[joint]]\nname = \"a6\"\nstiffness = 5.0e5\nbacklash = 3.0e-4\n";
    let combined = format!("{}\n{drive}", fuzz::KR300_STIFFNESS);
    write("drive_toml", "kr300_drive.toml", drive.as_bytes());
    write("drive_toml", "kr300_combined.toml", combined.as_bytes());

    // urdf_stiffness: URDF, NUL, stiffness TOML (with and without drive entries).
    write(
        "urdf_stiffness",
        "kr300",
        &fuzz::join_urdf_stiffness(fuzz::KR300_URDF, fuzz::KR300_STIFFNESS),
    );
    write(
        "urdf_stiffness",
        "kr300_drive",
        &fuzz::join_urdf_stiffness(fuzz::KR300_URDF, &combined),
    );
    // Springs placed at joints (`joint = "..."`) instead of inside links.
    let at_joints = "[[virtual_joint]]\njoint = \"a1\"\nk = [7.5e6, 1.2e7, 1.2e7]\n\n\
                     [[virtual_joint]]\njoint = \"a2\"\nk = [5.4e6, 6.1e6, 6.1e6]\n\n\
                     [[virtual_joint]]\nlink = \"link_2\"\nxyz = [0.575, 0.0, 0.0]\n\
                     k = [1.2e7, 3.8e6, 1.0e7]\n\n\
                     [[virtual_joint]]\njoint = \"a3\"\nk = [4.3e6, 6.2e6, 6.2e6]\n\n\
                     [[virtual_joint]]\njoint = \"a4\"\nk = [9.0e5, 3.0e6, 3.0e6]\n\n\
                     [[virtual_joint]]\njoint = \"a5\"\nk = [8.0e5, 2.5e6, 2.5e6]\n\n\
                     [[virtual_joint]]\njoint = \"a6\"\nk = [4.9e5, 6.7e5, 6.7e5]\n";
    write(
        "urdf_stiffness",
        "kr300_at_joints",
        &fuzz::join_urdf_stiffness(fuzz::KR300_URDF, at_joints),
    );
    // A small robot with what the KR 300 lacks: masses, a continuous and a prismatic joint.
    let small = r#"<?xml version="1.0"?>
<robot name="small">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="12.5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="slide"><inertial><origin xyz="0 0 0.1"/><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="tip"/>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="lift" type="prismatic">
    <parent link="arm"/><child link="slide"/>
    <origin xyz="0.4 0 0" rpy="0 1.5707963267948966 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.2" upper="0.3" effort="100" velocity="1"/>
  </joint>
  <joint name="flange" type="fixed">
    <parent link="slide"/><child link="tip"/>
    <origin xyz="0 0 0.15" rpy="0 0 0"/>
  </joint>
</robot>
"#;
    let small_stiffness = "[[virtual_joint]]\nlink = \"arm\"\nk = [1.0e6, 1.0e6, 5.0e5]\n\n\
                           [[virtual_joint]]\nlink = \"slide\"\nxyz = [0.0, 0.0, 0.05]\n\
                           rpy = [0.0, 0.0, 0.5]\nk = [2.0e5, inf, 3.0e5]\n\n\
                           [[joint]]\nname = \"spin\"\nstiffness = 2.0e5\nbacklash = 1.0e-3\n\n\
                           [[joint]]\nname = \"lift\"\nstiffness = 1.0e7\n";
    write(
        "urdf_stiffness",
        "small_masses",
        &fuzz::join_urdf_stiffness(small, small_stiffness),
    );

    // map_csv: the paper's tables, and a 2 x 2 table in metres with a comment.
    for name in [
        "paksoy2025_compliance_oc.csv",
        "paksoy2025_compliance_nc.csv",
    ] {
        write("map_csv", name, read(&format!("data/{name}")).as_bytes());
    }
    let small_table = "# 2 x 2 nodes, positions in m\n\
                       x_m,y_m,m,n,o,p,s,u,v,w\n\
                       0.1,0.0,1e-3,-2e-3,0.5e-3,1e-3,2e-3,0,-1e-3,3e-3\n\
                       0.1,0.1,1.1e-3,-2e-3,0.4e-3,1e-3,2e-3,0,-1e-3,3e-3\n\
                       0.2,0.0,1.2e-3,-2e-3,0.3e-3,1e-3,2e-3,0,-1e-3,3e-3\n\
                       0.2,0.1,1.3e-3,-2e-3,0.2e-3,1e-3,2e-3,0,-1e-3,3e-3\n";
    write("map_csv", "small_m.csv", small_table.as_bytes());

    // static_csv: readings of a 2 x 2 grid (mm), two force axes at two levels (N), from the
    // OC map's lines; and the same with named axes and a rotation column.
    let oc = map_csv::from_str(
        &read("data/paksoy2025_compliance_oc.csv"),
        ForceUnit::Newton,
        LengthUnit::Millimetre,
    )
    .unwrap();
    let mut rows = String::from("x,y,force_axis,force,dx,dy\n");
    let mut named = String::from("x,y,force_axis,force,dx,dy,rz\n");
    for i in 0..2 {
        for j in 0..2 {
            let (x, y) = (oc.x()[i] * 1e3, oc.y()[j] * 1e3);
            for f in 0..2 {
                for force in [50.0, 150.0, 250.0] {
                    let d: Vec<f64> = (0..2)
                        .map(|d| {
                            let (s, o) = (oc.slope(i, j, d, f).unwrap(), oc.offset(i, j, d, f));
                            (s * force + o.unwrap()) * 1e3
                        })
                        .collect();
                    rows.push_str(&format!("{x},{y},{f},{force},{:.6},{:.6}\n", d[0], d[1]));
                    let axis = ["x", "y"][f];
                    named.push_str(&format!(
                        "{x},{y},{axis},{force},{:.6},{:.6},{:.3e}\n",
                        d[0],
                        d[1],
                        d[0] * 1e-4
                    ));
                }
            }
        }
    }
    write("static_csv", "grid_2x2.csv", rows.as_bytes());
    write("static_csv", "grid_2x2_named.csv", named.as_bytes());

    // map_json: deflect's own JSON of the OC map, and of a fitted map (with statistics).
    write(
        "map_json",
        "paksoy2025_oc.json",
        map_json::to_string(&oc).unwrap().as_bytes(),
    );
    let fitted =
        map_csv::fit_static_str(&rows, ForceUnit::Newton, LengthUnit::Millimetre, None, 1e-6)
            .unwrap();
    write(
        "map_json",
        "fitted_2x2.json",
        map_json::to_string(&fitted).unwrap().as_bytes(),
    );
}
