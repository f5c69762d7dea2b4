//! Latency of one servo tick through deflect's C API (`deflect-ffi`, the extern "C"
//! functions a C controller links) next to the same tick through the Rust API, over 1e6
//! consecutive ticks: median, p99.9 and max. `cargo bench --bench ffi_latency` (optionally
//! `-- N` ticks). The C examples measure the same tick from C:
//! `bash examples/c/build_and_run.sh --latency 1000000`.
#![allow(unsafe_code)] // reason: calls the extern "C" API of deflect-ffi, as a C caller would.

use std::hint::black_box;
use std::ptr;

use deflect::*;
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::mechanism::ParallelRobot2;
use deflect_core::vjm::{self, Vector6};
use deflect_tests::{KR300_MILLING_POSE, MILLING_WRENCH, kr300, repo_path};
use nalgebra::Vector2;

fn c_path(rel: &str) -> std::ffi::CString {
    std::ffi::CString::new(repo_path(rel)).expect("no NUL in paths")
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let rt = deflect_tests::realtime_setup();
    println!("deflect C-API latency harness ({rt}; C API = extern \"C\" functions of deflect-ffi)");

    // --- The 2 kHz D'Alembert tick: sample the 5 g y-line, corrector step, one-shot. ---
    let map = deflect_tests::paper_oc_map_clamped();
    let view = map.view();
    let robot2 = ParallelRobot2::paper();
    let traj = deflect_tests::paper_y_line_5g();
    let period = traj.duration();
    let corr = Model::new(robot2, view, 5.0).expect("mass");
    // The corrector's data keeps the last tick's joints (the next IK seed).
    let mut corr_data = Data::new(&corr);
    let mut q2 = Vector2::zeros();
    deflect_tests::latency_report("rust: dalembert tick (sample+step)", n, None, |i| {
        let t = (i as f64 / 2000.0) % period;
        let s = traj.sample(black_box(t)).expect("in range");
        if let Ok(tick) = parallel::step(&corr, &mut corr_data, &s.position, &s.acceleration) {
            q2 = tick.joints;
        }
        black_box(q2);
    });

    let (mut cmap, mut ctraj, mut ccorr) = (ptr::null_mut(), ptr::null_mut(), ptr::null_mut());
    let mut lim = DeflectLimits::default();
    let csv = c_path("data/paksoy2025_compliance_oc.csv");
    // SAFETY: valid NUL-terminated strings, writable outputs, arrays of 2 doubles.
    unsafe {
        assert_eq!(
            deflect_compliance_map_load_paper_csv(
                csv.as_ptr(),
                DEFLECT_FORCE_UNIT_NEWTON,
                DEFLECT_LENGTH_UNIT_MILLIMETRE,
                &mut cmap,
                ptr::null_mut(),
                0
            ),
            DEFLECT_OK
        );
        deflect_compliance_map_set_options(
            cmap,
            DEFLECT_INTERPOLATION_BILINEAR,
            DEFLECT_OUT_OF_GRID_CLAMP,
        );
        deflect_paper_limits(5, &mut lim);
        let (a, b) = ([0.222132, -0.075], [0.222132, 0.075]);
        deflect_trajectory2_line(a.as_ptr(), b.as_ptr(), &lim, &mut ctraj);
        // The corrector copies the (clamping) map; it keeps the last tick's joints itself.
        deflect_dalembert_create(ptr::null(), cmap, DEFLECT_PAPER_MASS, 0, 0.0, &mut ccorr);
    }
    let mut q = [0.0; 2];
    let mut st = DeflectState2::default();
    let mut tick = DeflectCorrectedTick2::default();
    deflect_tests::latency_report("C API: dalembert tick (sample+step)", n, None, |i| {
        let t = (i as f64 / 2000.0) % period;
        // SAFETY: live handles from above, outputs are locals, arrays of 2 doubles.
        let ok = unsafe {
            deflect_trajectory2_sample(ctraj, black_box(t), &mut st) == DEFLECT_OK
                && deflect_dalembert_step(
                    ccorr,
                    st.position.as_ptr(),
                    st.acceleration.as_ptr(),
                    &mut tick,
                ) == DEFLECT_OK
        };
        if ok {
            q = tick.joints;
        }
        black_box(q);
    });

    // --- VJM deflection of the KR 300 (6 joints, 11 virtual joints). ---
    let robot = kr300();
    let mut data = vjm::Data::new(&robot.model);
    let w = Vector6::from_row_slice(&MILLING_WRENCH);
    let mut qk = KR300_MILLING_POSE;
    deflect_tests::latency_report("rust: vjm::deflection (KR 300)", n, None, |i| {
        qk[0] = 1e-6 * (i % 1000) as f64;
        black_box(
            vjm::deflection(
                &robot.model,
                &mut data,
                black_box(&qk),
                &w,
                vjm::Load::Exact,
            )
            .ok(),
        );
    });
    let mut crobot = ptr::null_mut();
    let (urdf, toml) = (
        c_path("robots/kr300/kr300_r2500.urdf"),
        c_path("robots/kr300/kr300_r2500_stiffness.toml"),
    );
    // SAFETY: valid NUL-terminated strings and a writable output.
    unsafe {
        assert_eq!(
            deflect_serial_robot_load(
                urdf.as_ptr(),
                toml.as_ptr(),
                c"tcp".as_ptr(),
                &mut crobot,
                ptr::null_mut(),
                0
            ),
            DEFLECT_OK
        );
    }
    let mut d = [0.0; 6];
    deflect_tests::latency_report("C API: deflect_serial_robot_deflection", n, None, |i| {
        qk[0] = 1e-6 * (i % 1000) as f64;
        // SAFETY: live handle, 6 joints, 6-wrench, 6 writable doubles.
        let s = unsafe {
            deflect_serial_robot_deflection(
                crobot,
                black_box(qk.as_ptr()),
                6,
                MILLING_WRENCH.as_ptr(),
                d.as_mut_ptr(),
            )
        };
        black_box((s, d));
    });

    // SAFETY: live handles, each freed once.
    unsafe {
        deflect_serial_robot_destroy(crobot);
        deflect_dalembert_destroy(ccorr);
        deflect_trajectory2_destroy(ctraj);
        deflect_compliance_map_destroy(cmap);
    }
}
