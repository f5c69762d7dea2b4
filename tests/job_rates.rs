//! The stock follows the programmed path between samples at any rate: at one sample per
//! second the last sample in a groove and the first after the retract and the rapid over the
//! stock are joined by a chord through the material the program never enters (the chord is a
//! rapid's: the job used to refuse it as a rapid into the stock). The job runs, the groove
//! has the programmed depth and ends where the program ends it, and the stock past it keeps
//! its top. The same program at 250 Hz cuts the same groove floor.

use deflect_core::machining::job::{self, Job};
use deflect_tests::{JOB_SEED, job_setup, kr300, read_mm as read};
use nalgebra::Vector2;

const CORNER: &str =
    "G21 G90\nG0 X-20 Y0 Z5\nM3 S13000\nG0 Z-2\nG1 X40 F1500\nG0 Z5\nG0 X60 Y10\nM5\n";

fn run(rate_hz: f64) -> job::Report {
    let mut setup = job_setup(Vector2::new(0.0, -0.015), Vector2::new(0.06, 0.015), 5.0e-4);
    setup.path.rate_hz = rate_hz;
    let robot = kr300();
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
    job::run(&job, &read(CORNER), &JOB_SEED).unwrap_or_else(|e| panic!("{rate_hz} Hz: {e}"))
}

#[test]
fn a_rapid_corner_at_one_sample_per_second_cuts_only_the_programmed_path() {
    let slow = run(1.0);
    let fast = run(250.0);
    assert!(slow.rapid_contact.is_none(), "{:?}", slow.rapid_contact);
    let z = &slow.nominal;
    // The groove's floor along y = 0 at the programmed depth, from the stock's edge to its
    // end at x = 40 mm (cells 0..80).
    let j = (0.015 / 5.0e-4) as usize;
    for i in [0, 20, 40, 70] {
        let h = z.height(i, j).unwrap();
        assert!((h + 0.002).abs() < 1e-12, "cell {i}: {h}");
        assert_eq!(h, fast.nominal.height(i, j).unwrap());
    }
    // Past the groove's end (x > 40 + 8 mm and its band) the stock keeps its top: nothing cut
    // along the chord from the groove to the rapid's end at (60, 10) mm.
    for i in 98..120 {
        for jj in 0..60 {
            assert_eq!(z.height(i, jj).unwrap(), 0.0, "cell ({i}, {jj})");
        }
    }
    assert!(slow.path_error(true).max < 1e-6);
}
