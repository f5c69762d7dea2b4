//! The committed header `include/deflect.h` must equal a fresh cbindgen generation, so it
//! never goes stale. `DEFLECT_BLESS=1 cargo test -p deflect-ffi --test header` rewrites it.

use std::path::PathBuf;

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
    String::from_utf8(out).unwrap()
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
        "#define DEFLECT_ERR_PANIC -99",
        "A required pointer argument",
        "DeflectStatus deflect_dalembert_step(",
        "DeflectStatus deflect_serial_robot_deflection(",
        "DeflectStatus deflect_compliance_map_displacement(",
        "typedef struct DeflectSerialRobot DeflectSerialRobot;",
        "typedef struct DeflectCompensator DeflectCompensator;",
        "DeflectStatus deflect_compensator_step(",
        "double residual[6][DEFLECT_RESIDUAL_TERMS];",
    ] {
        assert!(h.contains(needle), "header lacks `{needle}`");
    }
    // Every exported function of lib.rs appears in the header.
    let src = std::fs::read_to_string(crate_dir().join("src/lib.rs")).unwrap();
    for line in src.lines() {
        if let Some(rest) = line.split("extern \"C\" fn ").nth(1) {
            let name = rest.split('(').next().unwrap();
            assert!(h.contains(&format!("{name}(")), "header lacks {name}");
        }
    }
}
