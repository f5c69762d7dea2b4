//! After init, the per-tick functions of the C API allocate nothing: a counting global
//! allocator (counting on this test's thread only) sees zero allocations over whole loops.
#![allow(unsafe_code)] // reason: a counting global allocator and calls into the extern "C" API.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;
use std::ptr;

use deflect::*;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|a| a.set(a.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(p, layout) }
    }
    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|a| a.set(a.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(p, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

fn repo(rel: &str) -> std::ffi::CString {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel);
    std::ffi::CString::new(p.to_string_lossy().into_owned()).unwrap()
}

#[test]
fn per_tick_calls_do_not_allocate() {
    // Init: loads and plans allocate.
    let (urdf, toml, csv) = (
        repo("robots/kr300/kr300_r2500.urdf"),
        repo("robots/kr300/kr300_r2500_stiffness.toml"),
        repo("data/paksoy2025_compliance_oc.csv"),
    );
    let mut robot = ptr::null_mut();
    let mut map = ptr::null_mut();
    let mut traj = ptr::null_mut();
    let mut corr = ptr::null_mut();
    let mut comp = ptr::null_mut();
    let mut lim = DeflectLimits::default();
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        assert_eq!(
            deflect_serial_robot_load(
                urdf.as_ptr(),
                toml.as_ptr(),
                c"tcp".as_ptr(),
                &mut robot,
                ptr::null_mut(),
                0
            ),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_compliance_map_load_paper_csv(
                csv.as_ptr(),
                DEFLECT_FORCE_UNIT_NEWTON,
                DEFLECT_LENGTH_UNIT_MILLIMETRE,
                &mut map,
                ptr::null_mut(),
                0
            ),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_compliance_map_set_options(
                map,
                DEFLECT_INTERPOLATION_BILINEAR,
                DEFLECT_OUT_OF_GRID_CLAMP
            ),
            DEFLECT_OK
        );
        assert_eq!(deflect_paper_limits(5, &mut lim), DEFLECT_OK);
        let (a, b) = ([0.222132, -0.075], [0.222132, 0.075]);
        assert_eq!(
            deflect_trajectory2_line(a.as_ptr(), b.as_ptr(), &lim, &mut traj),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_dalembert_create(ptr::null(), map, DEFLECT_PAPER_MASS, 3, 0.0, &mut corr),
            DEFLECT_OK
        );
        let mut cfg = std::mem::MaybeUninit::<DeflectCompensatorConfig>::uninit();
        assert_eq!(
            deflect_compensator_config_paper(0.0005, cfg.as_mut_ptr()),
            DEFLECT_OK
        );
        let mut cfg = cfg.assume_init();
        cfg.output = DEFLECT_OUTPUT_JOINT;
        cfg.calibration.weight = 180.0;
        cfg.calibration.sensor_to_tcp_translation = [0.0, 0.0, 0.4];
        cfg.calibration.residual[2][5] = -1.5;
        assert_eq!(
            deflect_compensator_create(robot, &cfg, &mut comp),
            DEFLECT_OK
        );
    }

    let before = allocations();
    let mut q = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
    let w = [-386.1, 386.1, 0.0, 0.0, 0.0, 0.0];
    let (mut d, mut c) = ([0.0; 6], [0.0; 36]);
    let mut jc = DeflectJointCorrection::default();
    let mut n = 0usize;
    let mut st = DeflectState2::default();
    let mut tick = DeflectCorrectedTick2::default();
    let mut out = [0.0; 2];
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        for i in 0..200 {
            q[0] = 1e-4 * i as f64;
            assert_eq!(
                deflect_serial_robot_deflection(robot, q.as_ptr(), 6, w.as_ptr(), d.as_mut_ptr()),
                DEFLECT_OK
            );
            assert_eq!(
                deflect_serial_robot_compliance(robot, q.as_ptr(), 6, c.as_mut_ptr()),
                DEFLECT_OK
            );
            assert_eq!(
                deflect_serial_robot_linear_deflection(
                    robot,
                    q.as_ptr(),
                    6,
                    w.as_ptr(),
                    d.as_mut_ptr()
                ),
                DEFLECT_OK
            );
            assert_eq!(
                deflect_serial_robot_joint_correction(
                    robot,
                    q.as_ptr(),
                    6,
                    w.as_ptr(),
                    3,
                    0.0,
                    &mut jc
                ),
                DEFLECT_OK
            );
        }
        // Re-planning the handle in place allocates nothing: back and forth, then the move.
        let (a, b) = ([0.222132, -0.075], [0.222132, 0.075]);
        for (from, to) in [(b, a), (a, b)] {
            assert_eq!(
                deflect_trajectory2_replan_line(traj, from.as_ptr(), to.as_ptr(), &lim),
                DEFLECT_OK
            );
        }
        assert_eq!(
            deflect_trajectory2_tick_count(traj, 2000.0, &mut n),
            DEFLECT_OK
        );
        for k in 0..n {
            let mut t = 0.0;
            assert_eq!(
                deflect_trajectory2_tick_time(traj, 2000.0, k, &mut t),
                DEFLECT_OK
            );
            assert_eq!(deflect_trajectory2_sample(traj, t, &mut st), DEFLECT_OK);
            assert_eq!(
                deflect_dalembert_step(
                    corr,
                    st.position.as_ptr(),
                    st.acceleration.as_ptr(),
                    &mut tick
                ),
                DEFLECT_OK
            );
            assert_eq!(
                deflect_compliance_map_displacement(
                    map,
                    st.position.as_ptr(),
                    tick.force.as_ptr(),
                    2,
                    out.as_mut_ptr(),
                    2,
                    ptr::null_mut()
                ),
                DEFLECT_OK
            );
        }
        // The online compensation cycle: cutter exit at cycle 150, an estimate (pilot
        // control) that knows it 20 cycles early, joint output, a reset.
        let mut cycle = DeflectCycleOutput::default();
        let (mut samples, mut seconds) = (0.0, 0.0);
        assert_eq!(
            deflect_compensator_delay(comp, &mut samples, &mut seconds),
            DEFLECT_OK
        );
        for k in 0..300 {
            if k == 250 {
                assert_eq!(deflect_compensator_reset(comp), DEFLECT_OK);
            }
            q[0] = 1e-4 * k as f64;
            let f = if k < 150 { 800.0 } else { 0.0 };
            let reading = [0.5 * f, -0.7 * f, 180.0, 0.0, 0.02 * f, 0.0];
            let est = if k < 130 {
                [-400.0, 560.0, 0.0, 0.0, 0.0, 0.0]
            } else {
                [0.0; 6]
            };
            let feed = [0.0, 0.02, 0.0];
            assert_eq!(
                deflect_compensator_step(
                    comp,
                    q.as_ptr(),
                    6,
                    reading.as_ptr(),
                    if k % 2 == 0 {
                        est.as_ptr()
                    } else {
                        ptr::null()
                    },
                    feed.as_ptr(),
                    &mut cycle
                ),
                DEFLECT_OK
            );
        }
        assert!(cycle.dq.iter().any(|d| *d != 0.0));
        // Error paths do not allocate either.
        let nan6 = [f64::NAN; 6];
        let feed = [0.0; 3];
        assert_eq!(
            deflect_compensator_step(
                comp,
                q.as_ptr(),
                6,
                nan6.as_ptr(),
                ptr::null(),
                feed.as_ptr(),
                &mut cycle
            ),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_compensator_step(
                comp,
                q.as_ptr(),
                5,
                w.as_ptr(),
                ptr::null(),
                feed.as_ptr(),
                &mut cycle
            ),
            DEFLECT_ERR_WRONG_LENGTH
        );
        let nan = [f64::NAN; 2];
        assert_eq!(
            deflect_dalembert_step(corr, nan.as_ptr(), nan.as_ptr(), &mut tick),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_serial_robot_deflection(robot, q.as_ptr(), 5, w.as_ptr(), d.as_mut_ptr()),
            DEFLECT_ERR_WRONG_LENGTH
        );
    }
    assert_eq!(allocations() - before, 0, "per-tick C API calls allocated");
    assert!(n > 700);

    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        deflect_compensator_destroy(comp);
        deflect_dalembert_destroy(corr);
        deflect_trajectory2_destroy(traj);
        deflect_compliance_map_destroy(map);
        deflect_serial_robot_destroy(robot);
    }
}

#[test]
fn serial_corrector_ticks_do_not_allocate() {
    let (urdf, toml) = (
        repo("robots/kr300/kr300_r2500.urdf"),
        repo("robots/kr300/kr300_r2500_stiffness.toml"),
    );
    let q0 = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
    let payload = DeflectPayload {
        mass: 150.0,
        com: [0.0, 0.0, 0.25],
        inertia: [4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 2.5],
    };
    let lim = DeflectLimits {
        v_max: 2.0,
        a_max: 9.81,
        j_max: 200.0,
    };
    let (mut robot, mut motion, mut corr) = (ptr::null_mut(), ptr::null_mut(), ptr::null_mut());
    let (mut start, mut duration, mut n) = ([0.0; 16], 0.0, 0usize);
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        assert_eq!(
            deflect_serial_robot_load(
                urdf.as_ptr(),
                toml.as_ptr(),
                c"tcp".as_ptr(),
                &mut robot,
                ptr::null_mut(),
                0
            ),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_serial_robot_forward(robot, q0.as_ptr(), 6, start.as_mut_ptr()),
            DEFLECT_OK
        );
        let mut end = start;
        end[3] += 0.1;
        end[7] += 0.3;
        assert_eq!(
            deflect_pose_motion_line(start.as_ptr(), end.as_ptr(), &lim, &lim, &mut motion),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_pose_motion_info(motion, 2000.0, &mut duration, &mut n),
            DEFLECT_OK
        );
        assert_eq!(
            deflect_serial_dalembert_create(
                robot,
                &payload,
                DEFLECT_SERIAL_EXACT,
                q0.as_ptr(),
                6,
                &mut corr
            ),
            DEFLECT_OK
        );
    }
    let before = allocations();
    let (mut state, mut tick) = (DeflectPoseState::default(), DeflectSerialTick::default());
    let process = [0.0, 0.0, -300.0, 0.0, 0.0, 0.0];
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        for k in 0..n {
            let t = if k + 1 == n {
                duration
            } else {
                k as f64 / 2000.0
            };
            assert_eq!(
                deflect_pose_motion_sample(motion, t, &mut state),
                DEFLECT_OK
            );
            assert_eq!(
                deflect_serial_dalembert_step(corr, &state, process.as_ptr(), &mut tick),
                DEFLECT_OK
            );
        }
        state.acceleration[0] = f64::NAN;
        assert_eq!(
            deflect_serial_dalembert_step(corr, &state, ptr::null(), &mut tick),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_serial_dalembert_reset(corr, q0.as_ptr(), 6),
            DEFLECT_OK
        );
    }
    assert_eq!(allocations() - before, 0, "serial ticks allocated");
    assert!(n > 500);
    // SAFETY: live handles from this test.
    unsafe {
        deflect_serial_dalembert_destroy(corr);
        deflect_pose_motion_destroy(motion);
        deflect_serial_robot_destroy(robot);
    }
}
