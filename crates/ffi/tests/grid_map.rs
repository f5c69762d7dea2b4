//! Grid maps through the C API: a 3-D map loaded from its JSON answers as deflect-core does,
//! every bad input is a status.
#![allow(unsafe_code)] // reason: the tests call the extern "C" API, which is unsafe by nature.

use std::ffi::{CString, c_char};
use std::ptr;

use deflect::*;
use deflect_core::compliance_map::GridMap;
use deflect_core::io::map_json;

fn map3() -> GridMap {
    let axes = vec![
        vec![0.0, 0.1, 0.25],
        vec![-0.2, 0.0, 0.1, 0.3],
        vec![0.4, 0.5],
    ];
    let n = 3 * 4 * 2 * 2 * 3;
    let slopes: Vec<f64> = (0..n)
        .map(|k| 1e-6 * ((k * 37 % 17) as f64 - 8.0))
        .collect();
    let offsets: Vec<f64> = (0..n).map(|k| 1e-5 * ((k * 11 % 7) as f64 - 3.0)).collect();
    let names = ["x", "y", "z"].map(String::from).to_vec();
    GridMap::new(axes, names, 2, 3, slopes, offsets).unwrap()
}

#[test]
fn a_3d_map_answers_as_the_core() {
    let core = map3();
    let text = CString::new(map_json::grid_to_string(&core).unwrap()).unwrap();
    let mut m = ptr::null_mut();
    let mut err = [0 as c_char; 256];
    // SAFETY: NUL-terminated text, writable outputs of the stated sizes, live handles.
    unsafe {
        assert_eq!(
            deflect_grid_map_from_json(text.as_ptr(), &mut m, err.as_mut_ptr(), err.len()),
            DEFLECT_OK
        );
        let (mut dims, mut nf, mut nd) = (0usize, 0usize, 0usize);
        assert_eq!(
            deflect_grid_map_shape(m, &mut dims, &mut nf, &mut nd),
            DEFLECT_OK
        );
        assert_eq!((dims, nf, nd), (3, 2, 3));
        for interpolation in [
            DEFLECT_INTERPOLATION_BILINEAR,
            DEFLECT_INTERPOLATION_BICUBIC,
        ] {
            assert_eq!(
                deflect_grid_map_set_options(m, interpolation, DEFLECT_OUT_OF_GRID_ERROR),
                DEFLECT_OK
            );
            let core = core
                .clone()
                .with_options(deflect_core::compliance_map::QueryOptions {
                    interpolation: if interpolation == DEFLECT_INTERPOLATION_BILINEAR {
                        deflect_core::compliance_map::Interpolation::Bilinear
                    } else {
                        deflect_core::compliance_map::Interpolation::Bicubic
                    },
                    out_of_grid: deflect_core::compliance_map::OutOfGrid::Error,
                });
            for k in 0..50 {
                let t = k as f64 / 49.0;
                let p = [0.25 * t, -0.2 + 0.5 * (1.0 - t), 0.4 + 0.1 * t];
                let f = [100.0 - 3.0 * k as f64, 20.0];
                let (mut got, mut want) = ([0.0; 3], [0.0; 3]);
                let mut status = -1;
                assert_eq!(
                    deflect_grid_map_displacement(
                        m,
                        p.as_ptr(),
                        3,
                        f.as_ptr(),
                        2,
                        got.as_mut_ptr(),
                        3,
                        &mut status
                    ),
                    DEFLECT_OK
                );
                core.displacement(&p, &f, &mut want).unwrap();
                assert_eq!(got, want);
                assert_eq!(status, DEFLECT_QUERY_INSIDE);
            }
        }
        // Statuses: wrong lengths, non-finite, out of grid, options, NULL.
        let (p, f, mut o) = ([0.1, 0.0, 0.45], [1.0, 2.0], [0.0; 3]);
        let q = |p: &[f64], pl, fl, ol, o: &mut [f64; 3]| {
            deflect_grid_map_displacement(
                m,
                p.as_ptr(),
                pl,
                f.as_ptr(),
                fl,
                o.as_mut_ptr(),
                ol,
                ptr::null_mut(),
            )
        };
        assert_eq!(q(&p, 2, 2, 3, &mut o), DEFLECT_ERR_WRONG_LENGTH);
        assert_eq!(q(&p, 3, 1, 3, &mut o), DEFLECT_ERR_WRONG_LENGTH);
        assert_eq!(q(&p, 3, 2, 2, &mut o), DEFLECT_ERR_WRONG_LENGTH);
        assert_eq!(
            q(&[0.1, f64::NAN, 0.45], 3, 2, 3, &mut o),
            DEFLECT_ERR_NON_FINITE
        );
        assert_eq!(
            q(&[0.1, 0.0, 0.9], 3, 2, 3, &mut o),
            DEFLECT_ERR_OUT_OF_GRID
        );
        assert_eq!(
            deflect_grid_map_set_options(m, 7, 0),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_grid_map_set_options(m, 0, 7),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            deflect_grid_map_displacement(
                ptr::null(),
                p.as_ptr(),
                3,
                f.as_ptr(),
                2,
                o.as_mut_ptr(),
                3,
                ptr::null_mut()
            ),
            DEFLECT_ERR_NULL
        );
        assert_eq!(
            deflect_grid_map_shape(
                ptr::null(),
                ptr::null_mut(),
                ptr::null_mut(),
                ptr::null_mut()
            ),
            DEFLECT_ERR_NULL
        );
        deflect_grid_map_destroy(m);
        deflect_grid_map_destroy(ptr::null_mut());
        // A malformed document is a load failure with its message; *out stays NULL.
        let bad = CString::new("{\"format_version\": 2}").unwrap();
        let mut out = ptr::null_mut();
        assert_eq!(
            deflect_grid_map_from_json(bad.as_ptr(), &mut out, err.as_mut_ptr(), err.len()),
            DEFLECT_ERR_LOAD
        );
        assert!(out.is_null());
        let msg = std::ffi::CStr::from_ptr(err.as_ptr()).to_string_lossy();
        assert!(msg.contains("JSON"), "{msg}");
    }
}

#[test]
fn a_delta_and_its_corrector_answer_as_the_core() {
    use deflect_core::dalembert::parallel;
    use deflect_core::mechanism::Delta;
    use nalgebra::Vector3;
    let axes = vec![vec![-0.4, 0.4], vec![-0.4, 0.4], vec![-1.0, -0.5]];
    let slopes = [1e-6, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, 2e-6].repeat(8);
    let names = ["x", "y", "z"].map(String::from).to_vec();
    let core_map = GridMap::new(axes, names, 3, 3, slopes, vec![0.0; 72]).unwrap();
    let text = CString::new(map_json::grid_to_string(&core_map).unwrap()).unwrap();
    // SAFETY: writable outputs, readable inputs of the stated sizes, live handles.
    unsafe {
        let mut d = DeflectDelta {
            base_radius: 0.0,
            platform_radius: 0.0,
            arm: 0.0,
            forearm: 0.0,
            min_sigma: 0.0,
        };
        assert_eq!(deflect_delta_pick_and_place(&mut d), DEFLECT_OK);
        let p = [0.1, -0.05, -0.8];
        let (mut q, mut back) = ([0.0; 3], [0.0; 3]);
        assert_eq!(deflect_delta_ik(&d, p.as_ptr(), q.as_mut_ptr()), DEFLECT_OK);
        assert_eq!(
            deflect_delta_fk(&d, q.as_ptr(), back.as_mut_ptr()),
            DEFLECT_OK
        );
        let core = Delta::pick_and_place();
        assert_eq!(Vector3::from(q), core.ik(&Vector3::from(p)).unwrap());
        for (a, b) in back.iter().zip(&p) {
            assert!((a - b).abs() < 1e-12);
        }
        assert_eq!(
            deflect_delta_ik(&d, [0.0, 0.0, -1.5].as_ptr(), q.as_mut_ptr()),
            DEFLECT_ERR_OUT_OF_WORKSPACE
        );
        assert_eq!(
            deflect_delta_ik(ptr::null(), p.as_ptr(), q.as_mut_ptr()),
            DEFLECT_ERR_NULL
        );
        let bad = DeflectDelta { forearm: 0.1, ..d };
        assert_eq!(
            deflect_delta_ik(&bad, p.as_ptr(), q.as_mut_ptr()),
            DEFLECT_ERR_INVALID_ARGUMENT
        );
        let mut m = ptr::null_mut();
        let mut err = [0 as c_char; 256];
        assert_eq!(
            deflect_grid_map_from_json(text.as_ptr(), &mut m, err.as_mut_ptr(), err.len()),
            DEFLECT_OK
        );
        let mut c = ptr::null_mut();
        assert_eq!(
            deflect_delta_corrector_create(&d, m, 1.5, 0, 0.0, &mut c),
            DEFLECT_OK
        );
        let a = [0.0, 0.0, -8.0 * 9.81];
        let mut tick = DeflectCorrectedTick3::default();
        assert_eq!(
            deflect_delta_corrector_step(c, p.as_ptr(), a.as_ptr(), &mut tick),
            DEFLECT_OK
        );
        let model = parallel::Model::new(core, core_map, 1.5).unwrap();
        let mut data = parallel::Data::new(&model);
        let want = parallel::step(&model, &mut data, &Vector3::from(p), &Vector3::from(a)).unwrap();
        assert_eq!(Vector3::from(tick.joints), want.joints);
        assert_eq!(Vector3::from(tick.commanded), want.commanded);
        assert_eq!(tick.placement, DEFLECT_QUERY_INSIDE);
        // Out of the map's grid: a status; NULLs: statuses.
        assert_eq!(
            deflect_delta_corrector_step(c, [0.1, 0.0, -0.45].as_ptr(), a.as_ptr(), &mut tick),
            DEFLECT_ERR_OUT_OF_GRID
        );
        assert_eq!(
            deflect_delta_corrector_step(c, p.as_ptr(), a.as_ptr(), ptr::null_mut()),
            DEFLECT_ERR_NULL
        );
        let mut none = ptr::null_mut();
        assert_eq!(
            deflect_delta_corrector_create(&d, ptr::null(), 1.5, 0, 0.0, &mut none),
            DEFLECT_ERR_NULL
        );
        assert!(none.is_null());
        deflect_delta_corrector_destroy(c);
        deflect_grid_map_destroy(m);
    }
}
