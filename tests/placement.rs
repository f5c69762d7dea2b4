//! The placement search on the built-in job (the KR 300, `data/groove_and_pocket.nc`): its
//! coarse grid and compass refinement find the placement an exhaustive grid at the finest
//! spacing finds; the scores do not depend on the thread count or on a worker's copy of the
//! loads (bytes); a box out of reach and a bad box are typed errors.

use deflect_core::machining::placement::{self, PlacementBox, Problem};
use deflect_core::machining::spin::{LoadPath, SpinOptions};
use deflect_tests::JOB_SEED;

fn problem(optimise: bool) -> Problem {
    let (job, program) = deflect_tests::builtin_job();
    Problem::new(job, &program, &JOB_SEED, SpinOptions::default(), optimise).unwrap()
}

#[test]
fn the_search_finds_the_exhaustive_grids_best() {
    let p = problem(false);
    let coarse = PlacementBox {
        min: [2.25, -0.2, 0.92, 0.0],
        max: [2.55, 0.2, 0.92, 0.0],
        steps: [3, 3, 1, 1],
    };
    let evaluate = |ps: &[[f64; 4]]| -> Result<_, ()> { Ok(p.evaluate_all(ps, 2)) };
    let found = placement::search(&coarse, 3, evaluate).unwrap().unwrap();
    // The finest spacing the refinement reaches: 1/8 of the grid's.
    let fine = PlacementBox {
        steps: [17, 17, 1, 1],
        ..coarse
    };
    let all = p.evaluate_all(&fine.grid(), 2);
    let (bp, bs) = fine
        .grid()
        .into_iter()
        .zip(all)
        .filter(|(_, s)| s.feasible())
        .min_by(|a, b| a.1.rms.total_cmp(&b.1.rms))
        .unwrap();
    let (fp, fs) = found.best;
    assert!(
        fs.rms <= bs.rms * (1.0 + 1e-12),
        "search {fs:?} at {fp:?}, exhaustive {bs:?} at {bp:?}"
    );
    assert!(
        (fp[0] - bp[0]).abs() < 1e-9 && (fp[1] - bp[1]).abs() < 1e-9,
        "{fp:?} {bp:?}"
    );
    assert!(found.evaluations < 9 + 3 * 4 + 1);
    // The grid's spread: the placement matters.
    let worst = found
        .grid
        .iter()
        .map(|(_, s)| s.rms)
        .filter(|r| r.is_finite())
        .fold(0.0, f64::max);
    assert!(worst > 1.1 * fs.rms, "{worst:e} {:e}", fs.rms);
}

#[test]
fn scores_do_not_depend_on_threads_or_the_workers_copy() {
    let p = problem(true);
    let bx = PlacementBox {
        min: [2.35, -0.05, 0.90, -0.2],
        max: [2.45, 0.05, 0.94, 0.2],
        steps: [2, 2, 1, 2],
    };
    let grid = bx.grid();
    let one = p.evaluate_all(&grid, 1);
    let two = p.evaluate_all(&grid, 2);
    let bytes = p.loads().to_bytes();
    let loads = LoadPath::from_bytes(&bytes).unwrap();
    assert_eq!(&loads, p.loads());
    let (spin, optimise) = p.spin();
    let copy = Problem::from_parts(p.job().clone(), loads, p.seed().to_vec(), spin, optimise);
    let three = copy.evaluate_all(&grid, 3);
    for ((a, b), c) in one.iter().zip(&two).zip(&three) {
        assert_eq!(a.rms.to_bits(), b.rms.to_bits());
        assert_eq!(a.rms.to_bits(), c.rms.to_bits());
        assert_eq!(a.max.to_bits(), c.max.to_bits());
    }
    assert!(one.iter().all(|s| s.feasible()));
    // Damaged bytes are refused, never read.
    assert!(LoadPath::from_bytes(&bytes[..bytes.len() - 1]).is_err());
    assert!(LoadPath::from_bytes(b"DFLLOAD2").is_err());
}

#[test]
fn a_box_out_of_reach_or_malformed_is_refused() {
    let p = problem(false);
    let far = PlacementBox {
        min: [5.0, 5.0, 0.9, 0.0],
        max: [6.0, 6.0, 0.9, 0.0],
        steps: [2, 2, 1, 1],
    };
    let e = placement::search(&far, 2, |ps: &[[f64; 4]]| -> Result<_, ()> {
        Ok(p.evaluate_all(ps, 2))
    })
    .unwrap()
    .unwrap_err();
    assert!(e.to_string().contains("outside reach"), "{e}");
    for bad in [
        PlacementBox {
            min: [1.0, 0.0, 0.0, 0.0],
            max: [0.0, 0.0, 0.0, 0.0],
            steps: [2, 1, 1, 1],
        },
        PlacementBox {
            min: [f64::NAN, 0.0, 0.0, 0.0],
            max: [0.0; 4],
            steps: [1; 4],
        },
        PlacementBox {
            min: [0.0; 4],
            max: [0.0; 4],
            steps: [0, 1, 1, 1],
        },
        PlacementBox {
            min: [0.0; 4],
            max: [1.0; 4],
            steps: [1024, 1024, 2, 1],
        },
    ] {
        assert!(bad.validate().is_err(), "{bad:?}");
    }
}

#[test]
fn any_damage_to_the_loads_bytes_is_refused_or_read_whole_never_a_panic() {
    let p = problem(false);
    let bytes = p.loads().to_bytes();
    let mut rng = deflect_tests::uniform(7);
    let (mut refused, mut read) = (0, 0);
    for _ in 0..2000 {
        let mut b = bytes.clone();
        let flips = 1 + (rng(0.0, 4.0) as usize);
        for _ in 0..flips {
            let at = rng(0.0, b.len() as f64) as usize % b.len();
            b[at] = rng(0.0, 256.0) as u8;
        }
        if rng(0.0, 1.0) < 0.2 {
            b.truncate(rng(0.0, b.len() as f64) as usize);
        }
        match LoadPath::from_bytes(&b) {
            Ok(l) => {
                read += 1;
                assert_eq!(l.to_bytes(), b, "what reads writes back the same bytes");
            }
            Err(_) => refused += 1,
        }
    }
    assert!(refused > 100 && read > 100, "{refused} {read}");
}
