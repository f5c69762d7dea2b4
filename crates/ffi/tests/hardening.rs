//! The adversarial reproducers through the C API: each returns a status code, never a crash,
//! a hang or NaN with `DEFLECT_OK`.
#![allow(unsafe_code)] // reason: the tests call the extern "C" API, which is unsafe by nature.

use std::ffi::{CString, c_char};
use std::path::Path;
use std::ptr;

use deflect::*;

fn repo(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
        .to_string_lossy()
        .into_owned()
}

/// Loads a robot from texts written to temporary files; returns the status and the handle.
fn load(urdf: &str, toml: &str, tip: &str) -> (DeflectStatus, *mut DeflectSerialRobot, String) {
    let dir = std::env::temp_dir().join(format!("deflect-hardening-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = NEXT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let (u, t) = (
        dir.join(format!("r{k}-{}.urdf", urdf.len())),
        dir.join(format!("r{k}-{}.toml", toml.len())),
    );
    std::fs::write(&u, urdf).unwrap();
    std::fs::write(&t, toml).unwrap();
    let (u, t, tip) = (
        CString::new(u.to_string_lossy().as_bytes()).unwrap(),
        CString::new(t.to_string_lossy().as_bytes()).unwrap(),
        CString::new(tip).unwrap(),
    );
    let mut out = ptr::null_mut();
    let mut err = [0 as c_char; 512];
    // SAFETY: NUL-terminated strings, writable outputs of the stated sizes.
    let s = unsafe {
        deflect_serial_robot_load(
            u.as_ptr(),
            t.as_ptr(),
            tip.as_ptr(),
            &mut out,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    // SAFETY: NUL-terminated by the library.
    let msg = unsafe { std::ffi::CStr::from_ptr(err.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    (s, out, msg)
}

fn kr300() -> (String, String) {
    (
        std::fs::read_to_string(repo("robots/kr300/kr300_r2500.urdf")).unwrap(),
        std::fs::read_to_string(repo("robots/kr300/kr300_r2500_stiffness.toml")).unwrap(),
    )
}

#[test]
fn deep_urdf_is_a_load_error_not_a_segfault() {
    let deep = format!(
        "<robot name=\"r\">{}{}</robot>",
        "<a>".repeat(15_000),
        "</a>".repeat(15_000)
    );
    let (_, toml) = kr300();
    let (s, out, msg) = load(&deep, &toml, "tcp");
    assert_eq!(s, DEFLECT_ERR_LOAD);
    assert!(out.is_null());
    assert!(msg.contains("nesting depth"), "{msg}");
}

#[test]
fn absurd_origins_and_subnormal_stiffness_are_refused() {
    let (urdf, toml) = kr300();
    let far = urdf.replacen("xyz=\"0.350 0 0.675\"", "xyz=\"1e308 0 0.675\"", 1);
    assert_ne!(far, urdf);
    let (s, out, msg) = load(&far, &toml, "tcp");
    assert_eq!(s, DEFLECT_ERR_LOAD, "{msg}");
    assert!(out.is_null());
    let first_k = toml.find("\nk = [").unwrap() + 6;
    let tiny = format!(
        "{}5e-324{}",
        &toml[..first_k],
        &toml[first_k + toml[first_k..].find(',').unwrap()..]
    );
    let (s, out, msg) = load(&urdf, &tiny, "tcp");
    assert_eq!(s, DEFLECT_ERR_LOAD, "{msg}");
    assert!(out.is_null());
    assert!(msg.contains("5e-324"), "{msg}");
}

#[test]
fn huge_wrench_is_a_status_not_nan() {
    let (urdf, toml) = kr300();
    let (s, robot, msg) = load(&urdf, &toml, "tcp");
    assert_eq!(s, DEFLECT_OK, "{msg}");
    let q = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
    let mut out = [7.0; 6];
    for w in [[1e308, -1e308, 1e308, 0.0, 0.0, 0.0], [-1e308; 6]] {
        // SAFETY: live handle, arrays of the documented lengths.
        let s = unsafe {
            deflect_serial_robot_deflection(robot, q.as_ptr(), 6, w.as_ptr(), out.as_mut_ptr())
        };
        assert_eq!(s, DEFLECT_ERR_INVALID_ARGUMENT);
        assert_eq!(out, [7.0; 6], "outputs are written only on success");
    }
    // SAFETY: handle from load, freed once.
    unsafe { deflect_serial_robot_destroy(robot) };
}

#[test]
fn tick_count_of_an_absurd_motion_is_a_budget_error() {
    // 0.15 m at 1 um/s: 1.5e5 s (within MAX_DURATION), 1.5e13 ticks at 100 MHz.
    let limits = DeflectLimits {
        v_max: 1e-6,
        a_max: 49.05,
        j_max: 5207.0,
    };
    let (a, b) = ([0.2, -0.075], [0.2, 0.075]);
    let mut traj = ptr::null_mut();
    // SAFETY: arrays of 2, readable limits, writable handle pointer.
    assert_eq!(
        unsafe { deflect_trajectory2_line(a.as_ptr(), b.as_ptr(), &limits, &mut traj) },
        DEFLECT_OK
    );
    let mut count = 0usize;
    // SAFETY: live handle, writable output.
    let s = unsafe { deflect_trajectory2_tick_count(traj, 1e8, &mut count) };
    assert_eq!(s, DEFLECT_ERR_BUDGET);
    assert_eq!(count, 0);
    let sub = DeflectLimits {
        v_max: 5e-324,
        ..limits
    };
    let mut t2 = ptr::null_mut();
    // SAFETY: as above.
    let s = unsafe { deflect_trajectory2_line(a.as_ptr(), b.as_ptr(), &sub, &mut t2) };
    assert_eq!(s, DEFLECT_ERR_INVALID_ARGUMENT);
    assert!(t2.is_null());
    // Re-planning in place refuses the same limits, a NaN point and a NULL handle, and leaves
    // the plan as it was.
    let mut before = 0.0;
    // SAFETY: live handle, writable output.
    assert_eq!(
        unsafe { deflect_trajectory2_duration(traj, &mut before) },
        DEFLECT_OK
    );
    let nan = [f64::NAN, 0.0];
    // SAFETY: arrays of 2, readable limits; the handle is live or NULL.
    unsafe {
        assert_eq!(
            deflect_trajectory2_replan_line(traj, a.as_ptr(), b.as_ptr(), &sub),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_trajectory2_replan_line(traj, nan.as_ptr(), b.as_ptr(), &limits),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_trajectory2_replan_line(ptr::null_mut(), a.as_ptr(), b.as_ptr(), &limits),
            DEFLECT_ERR_NULL
        );
    }
    let mut after = 0.0;
    // SAFETY: live handle, writable output.
    assert_eq!(
        unsafe { deflect_trajectory2_duration(traj, &mut after) },
        DEFLECT_OK
    );
    assert_eq!(after.to_bits(), before.to_bits());
    // SAFETY: handle from line, freed once.
    unsafe { deflect_trajectory2_destroy(traj) };
}

#[test]
fn far_extrapolation_is_a_status_not_nan() {
    let path = CString::new(repo("data/paksoy2025_compliance_oc.csv")).unwrap();
    let mut map = ptr::null_mut();
    // SAFETY: NUL-terminated path, writable handle pointer, no message buffer.
    let s = unsafe {
        deflect_compliance_map_load_paper_csv(
            path.as_ptr(),
            DEFLECT_FORCE_UNIT_NEWTON,
            DEFLECT_LENGTH_UNIT_MILLIMETRE,
            &mut map,
            ptr::null_mut(),
            0,
        )
    };
    assert_eq!(s, DEFLECT_OK);
    // SAFETY: live handle.
    assert_eq!(
        unsafe {
            deflect_compliance_map_set_options(
                map,
                DEFLECT_INTERPOLATION_BILINEAR,
                DEFLECT_OUT_OF_GRID_EXTRAPOLATE,
            )
        },
        DEFLECT_OK
    );
    let (p, f) = ([1e300, -1e300], [1e300, 1e300]);
    let mut out = [0.0; 2];
    let mut status = -1;
    // SAFETY: arrays of the stated lengths.
    let s = unsafe {
        deflect_compliance_map_displacement(
            map,
            p.as_ptr(),
            f.as_ptr(),
            2,
            out.as_mut_ptr(),
            2,
            &mut status,
        )
    };
    assert_eq!(s, DEFLECT_ERR_NON_FINITE_OUTPUT);
    // SAFETY: handle from load, freed once.
    unsafe { deflect_compliance_map_destroy(map) };
}
