//! Error codes of the motion and corrector handles, contained panics, and a message for
//! every status.
#![allow(unsafe_code)] // reason: the tests call the extern "C" API, which is unsafe by nature.

use super::*;

#[test]
fn motion_and_corrector_errors() {
    let mut lim = DeflectLimits::default();
    // SAFETY: live handles from this test, arrays of the documented lengths.
    unsafe {
        assert_eq!(
            deflect_paper_limits(0, &mut lim),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(deflect_paper_limits(3, &mut lim), DEFLECT_OK);
        let mut t = ptr::null_mut();
        let pts = [0.19, -0.05, 0.25, 0.0, 0.19, 0.05, 0.19, -0.05];
        assert_eq!(
            deflect_trajectory2_polyline(pts.as_ptr(), 4, &lim, &mut t),
            DEFLECT_OK
        );
        let mut dur = 0.0;
        assert_eq!(deflect_trajectory2_duration(t, &mut dur), DEFLECT_OK);
        assert!(dur > 0.5 && dur < 1.0, "{dur}");
        let mut n = 0;
        assert_eq!(
            deflect_trajectory2_tick_count(t, 2000.0, &mut n),
            DEFLECT_OK
        );
        let mut last = 0.0;
        assert_eq!(
            deflect_trajectory2_tick_time(t, 2000.0, n - 1, &mut last),
            DEFLECT_OK
        );
        assert_eq!(last, dur);
        assert_eq!(
            deflect_trajectory2_tick_count(t, 0.0, &mut n),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        let mut st = DeflectState2::default();
        assert_eq!(deflect_trajectory2_sample(t, dur, &mut st), DEFLECT_OK);
        assert_eq!(st.position, [0.19, -0.05]);
        assert_eq!(
            deflect_trajectory2_sample(t, f64::INFINITY, &mut st),
            DEFLECT_ERR_NON_FINITE
        );
        deflect_trajectory2_destroy(t);

        let mut t2 = ptr::null_mut();
        assert_eq!(
            deflect_trajectory2_polyline(pts.as_ptr(), 1, &lim, &mut t2),
            DEFLECT_ERR_WRONG_LENGTH
        );
        assert!(t2.is_null());
        let bad = DeflectLimits { v_max: -1.0, ..lim };
        assert_eq!(
            deflect_trajectory2_line(pts.as_ptr(), pts[2..].as_ptr(), &bad, &mut t2),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        let nanp = [f64::NAN, 0.0];
        assert_eq!(
            deflect_trajectory2_line(nanp.as_ptr(), pts.as_ptr(), &lim, &mut t2),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_trajectory2_line(pts.as_ptr(), pts.as_ptr(), ptr::null(), &mut t2),
            DEFLECT_ERR_NULL
        );

        // The corrector takes its map at creation (a copy, with the map's options).
        let m = oc_map_c();
        let mut corr = ptr::null_mut();
        assert_eq!(
            deflect_dalembert_create(ptr::null(), m, -1.0, 0, 0.0, &mut corr),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_dalembert_create(ptr::null(), m, f64::NAN, 0, 0.0, &mut corr),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_dalembert_create(ptr::null(), m, 5.0, 3, -1.0, &mut corr),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        let mut geom = DeflectParallelRobot2 {
            link: 0.0,
            half_width: 0.0,
            min_sigma: 0.0,
        };
        assert_eq!(
            deflect_dalembert_create(&geom, m, 5.0, 0, 0.0, &mut corr),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert!(corr.is_null());
        assert_eq!(deflect_parallel_robot2_paper(&mut geom), DEFLECT_OK);
        assert_eq!(geom.link, 0.150);
        // A NULL map is refused at creation (it used to be a step argument).
        assert_eq!(
            deflect_dalembert_create(&geom, ptr::null(), 5.0, 3, 1e-12, &mut corr),
            DEFLECT_ERR_NULL
        );
        assert!(corr.is_null());
        // A map without 2 force and 2 displacement axes is refused at creation too.
        let one_axis = ComplianceMap::new(
            vec![0.1, 0.3],
            vec![-0.1, 0.1],
            1,
            1,
            vec![1e-6; 4],
            vec![0.0; 4],
        )
        .unwrap();
        let one_axis = c(&map_json::to_string(&one_axis).unwrap());
        let mut m1 = ptr::null_mut();
        assert_eq!(
            deflect_compliance_map_from_json(one_axis.as_ptr(), &mut m1, ptr::null_mut(), 0),
            DEFLECT_OK
        );
        let mut corr1 = ptr::NonNull::<DeflectDalembert>::dangling().as_ptr();
        assert_eq!(
            deflect_dalembert_create(&geom, m1, 5.0, 0, 0.0, &mut corr1),
            DEFLECT_ERR_MAP_DIMENSION
        );
        assert!(corr1.is_null(), "a failed create sets *out to NULL");
        deflect_compliance_map_destroy(m1);
        assert_eq!(
            deflect_dalembert_create(&geom, m, 5.0, 3, 1e-12, &mut corr),
            DEFLECT_OK
        );
        let (x, a) = ([0.222132, 0.0], [0.0, 5.0 * 9.81]);
        let mut tick = DeflectCorrectedTick2::default();
        assert_eq!(
            deflect_dalembert_step(corr, x.as_ptr(), a.as_ptr(), &mut tick),
            DEFLECT_OK
        );
        assert!(tick.iterations >= 1);
        assert_eq!(tick.force, [a[0] * -5.0, a[1] * -5.0]);
        assert_eq!(tick.placement, DEFLECT_QUERY_INSIDE);
        let nan = [f64::NAN, 0.0];
        assert_eq!(
            deflect_dalembert_step(corr, x.as_ptr(), nan.as_ptr(), &mut tick),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            deflect_dalembert_step(ptr::null_mut(), x.as_ptr(), a.as_ptr(), &mut tick),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_dalembert_step(corr, x.as_ptr(), a.as_ptr(), ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        // The default map policy refuses off-grid points.
        let off = [0.1, 0.0];
        assert_eq!(
            deflect_dalembert_step(corr, off.as_ptr(), a.as_ptr(), &mut tick),
            DEFLECT_ERR_OUT_OF_GRID
        );
        // The corrector owns its copy: destroying the map leaves it working.
        deflect_compliance_map_destroy(m);
        assert_eq!(
            deflect_dalembert_step(corr, x.as_ptr(), a.as_ptr(), &mut tick),
            DEFLECT_OK
        );
        assert_eq!(tick.force, [a[0] * -5.0, a[1] * -5.0]);
        deflect_dalembert_destroy(corr);
        deflect_dalembert_destroy(ptr::null_mut());
    }
}

#[test]
fn panics_are_contained_and_every_status_has_a_message() {
    assert_eq!(deflect_test_panic(), DEFLECT_ERR_PANIC);
    let name = |s| {
        // SAFETY: live handles from this test, arrays of the documented lengths.
        unsafe { CStr::from_ptr(deflect_status_message(s)) }
            .to_str()
            .unwrap()
    };
    let codes = [
        DEFLECT_OK,
        DEFLECT_ERR_NULL,
        DEFLECT_ERR_NON_FINITE,
        DEFLECT_ERR_WRONG_LENGTH,
        DEFLECT_ERR_LOAD,
        DEFLECT_ERR_OUT_OF_GRID,
        DEFLECT_ERR_OUT_OF_WORKSPACE,
        DEFLECT_ERR_SINGULAR,
        DEFLECT_ERR_NOT_CONVERGED,
        DEFLECT_ERR_INVALID_ARGUMENT,
        DEFLECT_ERR_MAP_DIMENSION,
        DEFLECT_ERR_OTHER,
        DEFLECT_ERR_PANIC,
    ];
    let mut names: Vec<&str> = codes.iter().map(|&s| name(s)).collect();
    assert!(names.iter().all(|n| *n != "unknown status"));
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), codes.len(), "distinct messages");
    assert_eq!(name(-1234), "unknown status");
    assert_eq!(
        // SAFETY: live handles from this test, arrays of the documented lengths.
        unsafe { CStr::from_ptr(deflect_version()) }
            .to_str()
            .unwrap(),
        env!("CARGO_PKG_VERSION")
    );
}

#[test]
fn the_new_status_codes_have_their_own_messages() {
    let name = |s| {
        // SAFETY: `deflect_status_message` returns a static NUL-terminated string.
        unsafe { CStr::from_ptr(deflect_status_message(s)) }
            .to_str()
            .unwrap()
    };
    let new = [
        (DEFLECT_ERR_NON_FINITE_OUTPUT, -11),
        (DEFLECT_ERR_NO_EDGE_MOTION, -12),
        (DEFLECT_ERR_JOINT_LIMIT, -13),
        (DEFLECT_ERR_BUDGET, -14),
        (DEFLECT_ERR_MODEL_MISMATCH, -15),
    ];
    let older: Vec<&str> = (-10..=0)
        .chain([DEFLECT_ERR_OTHER, DEFLECT_ERR_PANIC])
        .map(name)
        .collect();
    let mut names = Vec::new();
    for (code, value) in new {
        assert_eq!(code, value);
        let msg = name(code);
        assert_ne!(msg, "unknown status", "code {code}");
        assert!(!msg.is_empty(), "code {code}");
        assert!(
            !older.contains(&msg),
            "code {code} shares the message `{msg}`"
        );
        names.push(msg);
    }
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), new.len(), "distinct messages");
    assert_eq!(name(-16), "unknown status");
}
