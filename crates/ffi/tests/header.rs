//! The committed header `include/deflect.h` must equal a fresh cbindgen generation, so it
//! never goes stale. `DEFLECT_BLESS=1 cargo test -p deflect-ffi --test header` rewrites it.
//!
//! The crate is split into modules (`lib.rs` declares `pub mod status; ... mod boundary;`):
//! cbindgen starts at `lib.rs` and follows the `mod` declarations, and a test checks that
//! every exported function, handle, struct and constant of every module reaches the header.

use std::path::{Path, PathBuf};

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn generate() -> String {
    let dir = crate_dir();
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).unwrap();
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .unwrap();
    let mut out = Vec::new();
    bindings.write(&mut out);
    // The Rust docs escape unit brackets (`\[m\]`) so that rustdoc does not read them as
    // links; C readers get the plain `[m]`.
    String::from_utf8(out)
        .unwrap()
        .replace("\\[", "[")
        .replace("\\]", "]")
}

/// The header with every run of whitespace collapsed to one space, so that signatures can be
/// compared whatever line breaks cbindgen chose.
fn flat(h: &str) -> String {
    h.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Every `.rs` file of the crate's sources, sorted.
fn sources() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(&crate_dir().join("src"), &mut files);
    files.sort();
    files
}

/// The first identifier after `prefix` on each line of every source file.
fn declared(prefix: &str) -> Vec<(String, String)> {
    let mut names = Vec::new();
    for file in sources() {
        let text = std::fs::read_to_string(&file).unwrap();
        let src = crate_dir().join("src");
        let file_name = file
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        for line in text.lines() {
            if let Some(rest) = line.trim_start().strip_prefix(prefix) {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                names.push((file_name.clone(), name));
            }
        }
    }
    names
}

#[test]
fn committed_header_is_up_to_date() {
    let fresh = generate();
    let path = crate_dir().join("../../include/deflect.h");
    if std::env::var_os("DEFLECT_BLESS").is_some() {
        std::fs::write(&path, &fresh).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "include/deflect.h is stale: regenerate it with \
         `DEFLECT_BLESS=1 cargo test -p deflect-ffi --test header`"
    );
}

#[test]
fn header_carries_the_docs_and_every_entry_point() {
    let h = generate();
    for needle in [
        "#define DEFLECT_OK 0",
        "#define DEFLECT_ERR_MAP_DIMENSION -10",
        "#define DEFLECT_ERR_NON_FINITE_OUTPUT -11",
        "#define DEFLECT_ERR_NO_EDGE_MOTION -12",
        "#define DEFLECT_ERR_JOINT_LIMIT -13",
        "#define DEFLECT_ERR_BUDGET -14",
        "#define DEFLECT_ERR_MODEL_MISMATCH -15",
        "#define DEFLECT_ERR_PANIC -99",
        "A required pointer argument",
        "DeflectStatus deflect_dalembert_create(",
        "DeflectStatus deflect_dalembert_step(",
        "DeflectStatus deflect_serial_robot_deflection(",
        "DeflectStatus deflect_compliance_map_displacement(",
        "typedef struct DeflectSerialRobot DeflectSerialRobot;",
        "typedef struct DeflectDalembert DeflectDalembert;",
        "typedef struct DeflectCompensator DeflectCompensator;",
        "DeflectStatus deflect_compensator_step(",
        "double residual[6][DEFLECT_RESIDUAL_TERMS];",
        "int32_t placement;",
    ] {
        assert!(h.contains(needle), "header lacks `{needle}`");
    }
    assert!(!h.contains("model_status"), "renamed to `placement`");
    // Unit brackets read as in C, not as rustdoc escapes.
    assert!(
        !h.contains("\\[") && !h.contains("\\]"),
        "escaped brackets left"
    );
    assert!(h.contains("[m]"), "unit brackets missing");

    // The signatures that changed with the split into Model and Data: the corrector takes
    // its map at creation and is mutable per tick; the compensator owns its robot's chain.
    let f = flat(&h);
    for signature in [
        "DeflectStatus deflect_dalembert_create(const struct DeflectParallelRobot2 *robot, \
         const struct DeflectComplianceMap *map, double mass, \
         uint32_t fixed_point_iterations, double tolerance, struct DeflectDalembert **out);",
        "DeflectStatus deflect_dalembert_step(struct DeflectDalembert *corrector, \
         const double *desired, const double *acceleration, \
         struct DeflectCorrectedTick2 *out);",
        "DeflectStatus deflect_compensator_create(const struct DeflectSerialRobot *robot, \
         const struct DeflectCompensatorConfig *config, struct DeflectCompensator **out);",
        "DeflectStatus deflect_compensator_step(struct DeflectCompensator *compensator, \
         const double *q, size_t q_len, const double *reading, const double *estimated, \
         const double *feed_velocity, struct DeflectCycleOutput *out);",
        "DeflectStatus deflect_serial_robot_deflection(struct DeflectSerialRobot *robot, \
         const double *q, size_t q_len, const double *wrench, double *out);",
        "DeflectStatus deflect_compliance_map_displacement(\
         const struct DeflectComplianceMap *map, const double *position, \
         const double *force, size_t force_len, double *out, size_t out_len, \
         int32_t *status);",
        "const char *deflect_status_message(DeflectStatus status);",
    ] {
        assert!(
            f.contains(&flat(signature)),
            "header lacks the signature `{signature}`"
        );
    }

    // Every exported function, type and constant of every module appears in the header.
    let functions = declared("pub unsafe extern \"C\" fn ")
        .into_iter()
        .chain(declared("pub extern \"C\" fn "))
        .collect::<Vec<_>>();
    for (file, name) in &functions {
        assert!(name.starts_with("deflect_"), "{file}: {name}");
        assert!(
            h.contains(&format!("{name}(")),
            "header lacks {name} ({file})"
        );
    }
    for module in [
        "status.rs",
        "robot.rs",
        "map.rs",
        "motion.rs",
        "pose_motion.rs",
        "dalembert/parallel.rs",
        "dalembert/serial.rs",
        "compensation.rs",
    ] {
        assert!(
            functions.iter().any(|(file, _)| file == module),
            "no entry point found in {module}"
        );
    }
    assert!(functions.len() >= 35, "{} entry points", functions.len());
    for (file, name) in declared("pub struct ") {
        assert!(name.starts_with("Deflect"), "{file}: {name}");
        assert!(
            h.contains(&format!("typedef struct {name} ")),
            "header lacks {name} ({file})"
        );
    }
    for (file, name) in declared("pub type ") {
        assert!(name.starts_with("Deflect"), "{file}: {name}");
        assert!(
            h.contains(&format!(" {name};")),
            "header lacks {name} ({file})"
        );
    }
    for (file, name) in declared("pub const ") {
        assert!(name.starts_with("DEFLECT_"), "{file}: {name}");
        assert!(
            h.contains(&format!("#define {name} ")),
            "header lacks {name} ({file})"
        );
    }
}
