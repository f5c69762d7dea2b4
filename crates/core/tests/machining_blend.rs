//! Corner blending of the path model (`path::blend`): hand-derived overlap times, the
//! tolerance held, the feed never exceeded, the program's `G64 P` / `G61.1` honoured, and the
//! typed errors.

mod fixtures;

use deflect_core::BuildError;
use deflect_core::machining::Program;
use deflect_core::machining::path::{self, Blending, PathOptions, PathSample};
use deflect_core::motion::{Limits, Profile};
use fixtures::mm_program as program;
use nalgebra::Vector3;

/// Two 20 mm lines at a right angle, 25 mm/s, from (0, 0, 20) mm through the corner (20, 0, 20).
const L_PATH: &str = "G1 X20 F1500\nY20\n";

fn options(blending: Blending) -> PathOptions {
    PathOptions {
        rate_hz: 2000.0,
        blending,
        ..PathOptions::default()
    }
}

fn samples(p: &Program, blending: Blending) -> Vec<PathSample> {
    path::sample(p, &options(blending)).unwrap()
}

fn corner() -> Vector3<f64> {
    Vector3::new(0.02, 0.0, 0.02)
}

/// Distance of `x` from the segment `a`-`b`.
fn to_segment(x: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let d = b - a;
    let t = ((x - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
    (x - (a + d * t)).norm()
}

/// The rest-to-rest profile of one 20 mm line at 25 mm/s under the default limits.
fn line_profile() -> Profile {
    let d = PathOptions::default();
    Profile::new(0.02, &Limits::new(0.025, d.acceleration, d.jerk).unwrap()).unwrap()
}

#[test]
fn exact_stop_stops_at_the_corner_and_a_blend_does_not() {
    let p = program(L_PATH);
    let stop = samples(&p, Blending::ExactStop);
    let single = line_profile().duration();
    let total = path::duration(&p, &options(Blending::ExactStop)).unwrap();
    assert!((total - 2.0 * single).abs() < 1e-12, "{total} vs {single}");
    assert!(stop.iter().all(|s| !s.blend));
    // Somewhere at the corner the tool is at rest.
    let at_corner = stop
        .iter()
        .filter(|s| (s.position - corner()).norm() < 1e-9)
        .count();
    assert!(at_corner >= 1);

    // Blended within 0.1 mm: both ramps are the same, so the tail and the head are each
    // 0.05 mm; the ramp's first phase (jerk 20 m/s^3 for t_j = sqrt(v / j) = 35.4 ms) covers
    // j t^3 / 6 = 5e-5 m at t = (6 * 5e-5 / 20)^(1/3) = 24.66 ms.
    let tol = 1.0e-4;
    let overlap = (6.0 * 0.5 * tol / 20.0_f64).cbrt();
    assert!(overlap < (0.025_f64 / 20.0).sqrt());
    let blended_total = path::duration(&p, &options(Blending::Tolerance(tol))).unwrap();
    assert!(
        (blended_total - (2.0 * single - overlap)).abs() < 1e-9,
        "{blended_total} vs {}",
        2.0 * single - overlap
    );
    let blend = samples(&p, Blending::Tolerance(tol));
    let inside: Vec<&PathSample> = blend.iter().filter(|s| s.blend).collect();
    // 24.66 ms at 2 kHz: 49 or 50 samples in the blend.
    assert!((49..=50).contains(&inside.len()), "{}", inside.len());
    let (a, c, b) = (
        Vector3::new(0.0, 0.0, 0.02),
        corner(),
        Vector3::new(0.02, 0.02, 0.02),
    );
    let mut off = 0.0f64;
    for s in &blend {
        let from_path = to_segment(&s.position, &a, &c).min(to_segment(&s.position, &c, &b));
        off = off.max(from_path);
        if s.blend {
            assert!((s.position - c).norm() <= tol + 1e-15);
            // The tool keeps moving through the corner, no faster than the feed.
            assert!(s.speed > 1e-3, "{}", s.speed);
        }
        assert!(s.speed <= 0.025 + 1e-12);
    }
    // Off the path by more than a micrometre (it is a blend) and within the tolerance.
    assert!(off > 1e-6 && off <= tol, "{off}");
}

#[test]
fn a_blend_is_continuous_and_its_acceleration_is_the_two_runs_sum() {
    let p = program(L_PATH);
    let blend = samples(&p, Blending::Tolerance(1e-4));
    let dt = 1.0 / 2000.0;
    for w in blend.windows(3) {
        let [a, b, c] = [&w[0], &w[1], &w[2]];
        // Velocity and acceleration of the samples' positions (central differences).
        let v = (c.position - a.position) / (2.0 * dt);
        let acc = (c.position - b.position * 2.0 + a.position) / (dt * dt);
        let v_said = b.direction * b.speed;
        assert!((v - v_said).norm() < 2e-4, "t {}: {v} vs {v_said}", b.time);
        assert!(
            (acc - b.acceleration_vector).norm() < 0.05,
            "t {}: {acc} vs {}",
            b.time,
            b.acceleration_vector
        );
        assert!(b.acceleration_vector.norm() <= 2.0 * 2.0 + 1e-9);
    }
}

#[test]
fn zero_tolerance_overlaps_the_whole_ramp() {
    let p = program(L_PATH);
    let single = line_profile();
    let total = path::duration(&p, &options(Blending::Tolerance(0.0))).unwrap();
    let want = 2.0 * single.duration() - single.accel_time();
    assert!((total - want).abs() < 1e-12, "{total} vs {want}");
    // The speeds of the two ramps sum to the feed, so at the blend's middle (both at half
    // the feed, at right angles) the tool moves at 25 / sqrt(2) mm/s.
    let s = samples(&p, Blending::Tolerance(0.0));
    let slowest = s
        .iter()
        .filter(|s| s.blend)
        .map(|s| s.speed)
        .fold(f64::INFINITY, f64::min);
    assert!((slowest - 0.025 / 2.0_f64.sqrt()).abs() < 1e-6, "{slowest}");
}

#[test]
fn the_program_decides_where_it_says_so() {
    // G64 P0.1 (mm): the same as a tolerance of 1e-4 m for every corner.
    let g64 = program("G64 P0.1\nG1 X20 F1500\nY20\n");
    let own = samples(&g64, Blending::Program);
    let set = samples(&program(L_PATH), Blending::Tolerance(1e-4));
    assert_eq!(own.len(), set.len());
    for (a, b) in own.iter().zip(&set) {
        assert_eq!(a.position, b.position);
    }
    // G61.1 and G61: exact stops, bit for bit the stopping path.
    for mode in ["G61.1", "G61"] {
        let stopping = program(&format!("{mode}\nG1 X20 F1500\nY20\n"));
        let by_program = samples(&stopping, Blending::Program);
        let stop = samples(&stopping, Blending::ExactStop);
        assert_eq!(by_program, stop, "{mode}");
    }
    // Without G64 P the program's state is LinuxCNC's start: G64, as fast as possible.
    let plain = path::duration(&program(L_PATH), &options(Blending::Program)).unwrap();
    let fastest = path::duration(&program(L_PATH), &options(Blending::Tolerance(0.0))).unwrap();
    assert_eq!(plain, fastest);
}

#[test]
fn a_dwell_is_an_exact_stop() {
    let p = program("G1 X20 F1500\nG4 P0.5\nY20\n");
    let s = samples(&p, Blending::Tolerance(0.0));
    assert!(s.iter().all(|s| !s.blend));
    let stop = path::duration(&p, &options(Blending::ExactStop)).unwrap();
    let blended = path::duration(&p, &options(Blending::Tolerance(0.0))).unwrap();
    assert_eq!(stop, blended);
}

#[test]
fn bad_tolerances_are_typed_errors() {
    let p = program(L_PATH);
    for bad in [-1e-6, f64::NAN, f64::INFINITY, 0.2] {
        let e = path::sample(&p, &options(Blending::Tolerance(bad))).unwrap_err();
        assert!(
            matches!(e, BuildError::InvalidParameter { what, .. } if what == "blending tolerance"),
            "{bad}: {e:?}"
        );
    }
    // 30 mm at a corner of two 20 mm moves: past both.
    let e = path::sample(&p, &options(Blending::Tolerance(0.03))).unwrap_err();
    assert!(
        matches!(e, BuildError::InvalidEntry { index: 1, value, .. } if value == 0.03),
        "{e:?}"
    );
    // The program's own: G64 P30 (mm) on line 1.
    let e = path::sample(
        &program("G64 P30\nG1 X20 F1500\nY20\n"),
        &options(Blending::Program),
    )
    .unwrap_err();
    assert!(
        matches!(e, BuildError::InvalidEntry { index: 2, .. }),
        "{e:?}"
    );
}
