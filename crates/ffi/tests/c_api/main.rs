//! The extern "C" functions called from Rust: results equal the Rust API's bit for bit,
//! every documented error code comes back for its cause, loaders fill the message buffer.
#![allow(unsafe_code)] // reason: the tests call the extern "C" API, which is unsafe by nature.

use std::ffi::{CStr, CString, c_char};
use std::path::Path;
use std::ptr;

use deflect::*;
use deflect_core::SerialRobot;
use deflect_core::compliance_map::ComplianceMap;
use deflect_core::io::{map_csv, map_json};
use deflect_core::units::{ForceUnit, LengthUnit};
use deflect_core::vjm::{self, Data, Vector6};

const Q: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
const WRENCH: [f64; 6] = [-386.1, 386.1, 0.0, 0.0, 0.0, 0.0];

fn repo(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
        .to_string_lossy()
        .into_owned()
}

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

fn kr300_c() -> *mut DeflectSerialRobot {
    let (urdf, toml) = (
        c(&repo("robots/kr300/kr300_r2500.urdf")),
        c(&repo("robots/kr300/kr300_r2500_stiffness.toml")),
    );
    let mut out = ptr::null_mut();
    let mut err = [0 as c_char; 256];
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_serial_robot_load(
            urdf.as_ptr(),
            toml.as_ptr(),
            c"tcp".as_ptr(),
            &mut out,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_OK);
    assert!(!out.is_null());
    out
}

fn kr300_rust() -> SerialRobot {
    SerialRobot::from_path(
        repo("robots/kr300/kr300_r2500.urdf"),
        repo("robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )
    .unwrap()
}

fn oc_map_c() -> *mut DeflectComplianceMap {
    let path = c(&repo("data/paksoy2025_compliance_oc.csv"));
    let mut out = ptr::null_mut();
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_compliance_map_load_paper_csv(
            path.as_ptr(),
            DEFLECT_FORCE_UNIT_NEWTON,
            DEFLECT_LENGTH_UNIT_MILLIMETRE,
            &mut out,
            ptr::null_mut(),
            0,
        )
    };
    assert_eq!(s, DEFLECT_OK);
    out
}

#[test]
fn vjm_through_the_c_api_equals_the_rust_api() {
    let r = kr300_c();
    let rust = kr300_rust();
    let mut data = Data::new(&rust.model);
    let (mut dof, mut springs) = (0usize, 0usize);
    assert_eq!(
        // SAFETY: live handles from this test, arrays of the documented lengths.
        unsafe { deflect_serial_robot_dof(r, &mut dof, &mut springs) },
        DEFLECT_OK
    );
    assert_eq!((dof, springs), (6, 11));

    // The exact and the linearized deflection: each the Rust API's numbers.
    type Call = unsafe extern "C" fn(
        *mut DeflectSerialRobot,
        *const f64,
        usize,
        *const f64,
        *mut f64,
    ) -> DeflectStatus;
    let calls: [(Call, vjm::Load<'_>); 2] = [
        (deflect_serial_robot_deflection, vjm::Load::Exact),
        (
            deflect_serial_robot_linear_deflection,
            vjm::Load::Linearized,
        ),
    ];
    let mut both = [[0.0; 6]; 2];
    for ((call, load), d) in calls.into_iter().zip(&mut both) {
        // SAFETY: live handles from this test, arrays of the documented lengths.
        let s = unsafe { call(r, Q.as_ptr(), 6, WRENCH.as_ptr(), d.as_mut_ptr()) };
        assert_eq!(s, DEFLECT_OK);
        let want = vjm::deflection(&rust.model, &mut data, &Q, &Vector6::from(WRENCH), load);
        assert_eq!(*d, <[f64; 6]>::from(want.unwrap()), "{load:?}");
    }
    let [mut d, lin] = both;
    assert!(
        (d[0] - (-0.871e-3)).abs() < 1e-6,
        "README figure: dx = -0.871 mm, got {}",
        d[0]
    );

    let mut cm = [0.0; 36];
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe { deflect_serial_robot_compliance(r, Q.as_ptr(), 6, cm.as_mut_ptr()) };
    assert_eq!(s, DEFLECT_OK);
    let want = vjm::compliance(&rust.model, &mut data, &Q).unwrap();
    for i in 0..6 {
        for j in 0..6 {
            assert_eq!(cm[6 * i + j], want[(i, j)], "row-major C[{i}][{j}]");
        }
    }

    let lin = Vector6::from(lin);
    let cw = lin - nalgebra::Matrix6::from_row_slice(&cm) * Vector6::from(WRENCH);
    assert!(cw.amax() <= 1e-14 * lin.amax(), "C w: {cw}");
    let mut lin = [0.0; 6];
    let far = WRENCH.map(|v| v * 1e6);
    let mut bad_q = Q;
    bad_q[1] = f64::INFINITY;
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        let lin = lin.as_mut_ptr();
        let w = WRENCH.as_ptr();
        assert_eq!(
            deflect_serial_robot_linear_deflection(r, Q.as_ptr(), 6, far.as_ptr(), lin),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_serial_robot_linear_deflection(r, bad_q.as_ptr(), 6, w, lin),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_serial_robot_linear_deflection(r, Q.as_ptr(), 5, w, lin),
            DEFLECT_ERR_WRONG_LENGTH
        );
        assert_eq!(
            deflect_serial_robot_linear_deflection(r, Q.as_ptr(), 6, w, ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
    }

    let mut jc = DeflectJointCorrection::default();
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_serial_robot_joint_correction(r, Q.as_ptr(), 6, WRENCH.as_ptr(), 5, 1e-12, &mut jc)
    };
    assert_eq!(s, DEFLECT_OK);
    let want = vjm::joint_correction(&rust.model, &mut data, &Q, &Vector6::from(WRENCH), 5, 1e-12)
        .unwrap();
    assert_eq!(jc.dq, want.dq);
    assert_eq!(jc.iterations as usize, want.iterations);
    assert_eq!(jc.converged, i32::from(want.converged));

    // Per-tick errors.
    let mut bad = Q;
    bad[2] = f64::NAN;
    let w = WRENCH.as_ptr();
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        assert_eq!(
            deflect_serial_robot_deflection(r, bad.as_ptr(), 6, w, d.as_mut_ptr()),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_serial_robot_deflection(r, Q.as_ptr(), 5, w, d.as_mut_ptr()),
            DEFLECT_ERR_WRONG_LENGTH
        );
        assert_eq!(
            deflect_serial_robot_deflection(r, Q.as_ptr(), 6, ptr::null(), d.as_mut_ptr()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_robot_deflection(ptr::null_mut(), Q.as_ptr(), 6, w, d.as_mut_ptr()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_robot_compliance(r, Q.as_ptr(), 6, ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_serial_robot_joint_correction(r, Q.as_ptr(), 6, w, 1, f64::NAN, &mut jc),
            DEFLECT_ERR_NON_FINITE
        );
        // A stretched-out arm (all joints 0 puts A3..A5 in line): no unique correction.
        let zero = [0.0; 6];
        assert_eq!(
            deflect_serial_robot_joint_correction(r, zero.as_ptr(), 6, w, 1, 0.0, &mut jc),
            DEFLECT_ERR_SINGULAR
        );
        deflect_serial_robot_destroy(r);
        deflect_serial_robot_destroy(ptr::null_mut());
    }
}

#[test]
fn loaders_report_their_errors_in_the_callers_buffer() {
    let mut out = ptr::null_mut::<DeflectSerialRobot>();
    let mut err = [0 as c_char; 64];
    let missing = c("/nonexistent/robot.urdf");
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_serial_robot_load(
            missing.as_ptr(),
            missing.as_ptr(),
            c"tcp".as_ptr(),
            &mut out,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_ERR_LOAD);
    assert!(out.is_null());
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let msg = unsafe { CStr::from_ptr(err.as_ptr()) }.to_str().unwrap();
    assert!(
        msg.starts_with("cannot read /nonexistent/robot.urdf"),
        "{msg}"
    );
    assert_eq!(msg.len(), 63, "truncated to the buffer with its NUL");

    // NULL strings and a NULL output handle.
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_serial_robot_load(
            ptr::null(),
            missing.as_ptr(),
            c"tcp".as_ptr(),
            &mut out,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_ERR_NULL);
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let msg = unsafe { CStr::from_ptr(err.as_ptr()) }.to_str().unwrap();
    assert_eq!(msg, "urdf_path is NULL");
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_compliance_map_from_json(c"{}".as_ptr(), ptr::null_mut(), ptr::null_mut(), 0)
    };
    assert_eq!(s, DEFLECT_ERR_NULL);

    // A bad CSV, a bad unit code, a string that is not UTF-8.
    let mut map = ptr::null_mut();
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_compliance_map_from_paper_csv(
            c"x_mm,y_mm\n1,2\n".as_ptr(),
            0,
            1,
            &mut map,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_ERR_LOAD);
    assert!(map.is_null());
    // SAFETY: live handles from this test, arrays of the documented lengths.
    assert!(unsafe { CStr::from_ptr(err.as_ptr()) }.to_bytes().len() > 5);
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_compliance_map_from_paper_csv(
            c"x".as_ptr(),
            7,
            1,
            &mut map,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_ERR_INVALID_ARGUMENT);
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_compliance_map_from_json(
            c"\xff\xfe".as_ptr(),
            &mut map,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_ERR_INVALID_ARGUMENT);
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_compliance_map_load_json(
            c"/nonexistent.json".as_ptr(),
            &mut map,
            err.as_mut_ptr(),
            err.len(),
        )
    };
    assert_eq!(s, DEFLECT_ERR_LOAD);
}

#[test]
fn compliance_map_through_the_c_api_equals_the_rust_api() {
    let m = oc_map_c();
    let text = std::fs::read_to_string(repo("data/paksoy2025_compliance_oc.csv")).unwrap();
    let rust = map_csv::from_str(&text, ForceUnit::Newton, LengthUnit::Millimetre).unwrap();
    let (mut nf, mut nd) = (0, 0);
    assert_eq!(
        // SAFETY: live handles from this test, arrays of the documented lengths.
        unsafe { deflect_compliance_map_axes(m, &mut nf, &mut nd) },
        DEFLECT_OK
    );
    assert_eq!((nf, nd), (2, 2));
    let p = [0.2, 0.01];
    let f = [-49.05, 12.0];
    let (mut out, mut want) = ([0.0; 2], [0.0; 2]);
    let mut status = -1;
    // SAFETY: live handles from this test, arrays of the documented lengths.
    let s = unsafe {
        deflect_compliance_map_displacement(
            m,
            p.as_ptr(),
            f.as_ptr(),
            2,
            out.as_mut_ptr(),
            2,
            &mut status,
        )
    };
    assert_eq!(s, DEFLECT_OK);
    assert_eq!(status, DEFLECT_QUERY_INSIDE);
    rust.displacement(p, &f, &mut want).unwrap();
    assert_eq!(out, want);

    // JSON round trip through the C loader, then bicubic + extrapolation options.
    let json = c(&map_json::to_string(&rust).unwrap());
    let mut m2 = ptr::null_mut();
    assert_eq!(
        // SAFETY: live handles from this test, arrays of the documented lengths.
        unsafe { deflect_compliance_map_from_json(json.as_ptr(), &mut m2, ptr::null_mut(), 0) },
        DEFLECT_OK
    );
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        assert_eq!(
            deflect_compliance_map_set_options(
                m2,
                DEFLECT_INTERPOLATION_BICUBIC,
                DEFLECT_OUT_OF_GRID_EXTRAPOLATE
            ),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_compliance_map_set_options(m2, 2, 0),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_compliance_map_set_options(m2, 0, 3),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        let far = [0.4, 0.0];
        let s = deflect_compliance_map_displacement(
            m2,
            far.as_ptr(),
            f.as_ptr(),
            2,
            out.as_mut_ptr(),
            2,
            &mut status,
        );
        assert_eq!((s, status), (DEFLECT_OK, DEFLECT_QUERY_EXTRAPOLATED));
        assert_eq!(
            deflect_compliance_map_displacement(
                m,
                far.as_ptr(),
                f.as_ptr(),
                2,
                out.as_mut_ptr(),
                2,
                ptr::null_mut()
            ),
            DEFLECT_ERR_OUT_OF_GRID
        );
        assert_eq!(
            deflect_compliance_map_displacement(
                m,
                p.as_ptr(),
                f.as_ptr(),
                2,
                out.as_mut_ptr(),
                1,
                ptr::null_mut()
            ),
            DEFLECT_ERR_WRONG_LENGTH
        );
        let nan = [f64::NAN, 0.0];
        assert_eq!(
            deflect_compliance_map_displacement(
                m,
                nan.as_ptr(),
                f.as_ptr(),
                2,
                out.as_mut_ptr(),
                2,
                ptr::null_mut()
            ),
            DEFLECT_ERR_NON_FINITE
        );
        deflect_compliance_map_destroy(m2);
        deflect_compliance_map_destroy(m);
    }
}

mod statuses;
