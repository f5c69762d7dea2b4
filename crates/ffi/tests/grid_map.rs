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
