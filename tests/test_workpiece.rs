//! The shipped test workpiece (`data/test_workpiece.nc`, the milling scenario's program) on
//! the KR 300 job of `deflect-sim job`: mid-groove and mid-ramp forces against the slotting
//! closed form by hand (Altintas, "Manufacturing Automation", 2nd ed., eq. 2.14-2.16) at each
//! groove's depth and feed direction, the pocket its helical entry and last turn leave (a
//! floor at the last turn's depth within 16 mm of its centre, the top past it), and the
//! compensated prediction on the program.

use std::f64::consts::PI;

use deflect_core::machining::cutting::Coefficients;
use deflect_core::machining::job::{self, Job, PREDICTION_TOLERANCE};
use deflect_tests::{JOB_SEED, job_setup, kr300, read_mm as read, repo_path};
use nalgebra::{Vector2, Vector3};

/// The slot force in the tool frame (feed +x) at depth `a` and feed per tooth `c`: N = 3.
fn slot(a: f64, c: f64) -> Vector3<f64> {
    let k = Coefficients::AL7075_T6_CARBIDE;
    let n = 3.0;
    Vector3::new(
        -n * a * k.k_rc * c / 4.0 - n * a * k.k_re / PI,
        n * a * k.k_tc * c / 4.0 + n * a * k.k_te / PI,
        n * a * k.k_ac * c / PI + n * a * k.k_ae / 2.0,
    )
}

#[test]
fn the_test_workpieces_grooves_and_ramp_feel_the_slot_closed_form() {
    let text = std::fs::read_to_string(repo_path("data/test_workpiece.nc")).unwrap();
    let program = read(&text);
    let setup = job_setup(Vector2::new(0.0, 0.0), Vector2::new(0.14, 0.13), 5.0e-4);
    let robot = kr300();
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
    let r = job::run(&job, &program, &JOB_SEED).unwrap();
    let c = 0.025 / (13000.0 / 60.0 * 3.0);
    // The sample nearest (x, y) [m] on the feed moves at full feed.
    let at = |x: f64, y: f64| {
        r.samples
            .iter()
            .filter(|s| s.path.feed_move && (s.path.speed - 0.025).abs() < 1e-9)
            .min_by(|p, q| {
                let d = |s: &job::JobSample| (s.path.position.xy() - Vector2::new(x, y)).norm();
                d(p).total_cmp(&d(q))
            })
            .unwrap()
    };
    let close = |got: Vector3<f64>, want: Vector3<f64>, what: &str| {
        assert!(
            (got - want).norm() < 1e-9 * want.norm(),
            "{what}: {got} vs {want}"
        );
    };
    // Groove 1: 5 mm deep along +x.
    let g1 = at(0.07, 0.02);
    assert!((g1.path.position.z + 0.005).abs() < 1e-12);
    close(g1.force, slot(0.005, c), "groove 1");
    // Groove 2: 8 mm deep along -x: the tool frame turned half a turn about z.
    let g2 = at(0.07, 0.05);
    let s2 = slot(0.008, c);
    close(g2.force, Vector3::new(-s2.x, -s2.y, s2.z), "groove 2");
    // The ramp from 2 to 8 mm over 100 mm: the slot of the depth where the tip is, at the
    // horizontal part of the feed.
    let ramp = at(0.05, 0.08);
    let a = -ramp.path.position.z;
    assert!(a > 0.004 && a < 0.006, "{a}");
    let horizontal = 100.0 / (100.0f64.powi(2) + 6.0f64.powi(2)).sqrt();
    close(ramp.force, slot(a, c * horizontal), "ramp");
    // The pocket after its helical entry: every point within 16 mm of (70, 110) mm lies
    // within the 8 mm tool of the 8 mm circle its last turn runs at 6 mm, so the floor there
    // is at -6 mm; past 16 mm and the rim's half-cell band the stock keeps its top.
    let z = &r.nominal;
    let (mut floor, mut top) = (0, 0);
    for i in 0..280 {
        for j in 0..260 {
            let c = z.center(i, j) - Vector2::new(0.07, 0.11);
            let rho = c.norm();
            let h = z.height(i, j).unwrap();
            if rho < 0.016 - 3.6e-4 {
                assert!((h + 0.006).abs() < 1e-12, "({i}, {j}) at {rho}: {h}");
                floor += 1;
            } else if rho > 0.016 + 3.6e-4 && rho < 0.019 {
                assert_eq!(h, 0.0, "({i}, {j}) at {rho}");
                top += 1;
            }
        }
    }
    assert!(floor > 3000 && top > 900, "{floor} {top}");
    // The whole program compensated onto the program.
    assert!(
        r.path_error(true).max < PREDICTION_TOLERANCE,
        "{:?}",
        r.path_error(true)
    );
    assert!(r.path_error(false).max > 1e-4);
}
