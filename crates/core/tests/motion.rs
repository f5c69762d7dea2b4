//! Jerk-limited rest-to-rest profiles: closed-form hand cases, limits, endpoints, the
//! paper's motion durations, validation.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use approx::assert_relative_eq;
use deflect_core::motion::{
    self, Limits, MAX_POINTS, PAPER_ACCEL_TIMES, PAPER_G, PAPER_X_DURATIONS, PAPER_Y_DURATIONS,
    PreparedLimits, Profile, Trajectory,
};
use deflect_core::{BuildError, TickError};
use nalgebra::{SVector, Vector2, Vector3};
use proptest::prelude::*;

fn lim(v: f64, a: f64, j: f64) -> Limits {
    Limits::new(v, a, j).unwrap()
}

/// Samples a profile densely (and right at each phase boundary) and checks the limits, the
/// monotonicity of s, and that v and a are the derivatives of s and v.
fn check_profile(p: &Profile, l: &Limits) {
    let tol = 1.0e-9;
    let total = p.duration();
    let n = 4000;
    let mut t_list: Vec<f64> = (0..=n).map(|k| total * k as f64 / n as f64).collect();
    let mut acc = 0.0;
    for d in p.phase_durations() {
        acc += d;
        t_list.extend([acc - 1e-12, acc, acc + 1e-12]);
    }
    let mut prev_s = -1.0;
    t_list.sort_by(f64::total_cmp);
    for &t in &t_list {
        let s = p.sample(t);
        assert!(
            s.v <= l.v_max * (1.0 + tol) && s.v >= -tol,
            "v {} at {t}",
            s.v
        );
        assert!(s.a.abs() <= l.a_max * (1.0 + tol), "a {} at {t}", s.a);
        assert!(s.j.abs() <= l.j_max * (1.0 + tol), "j {} at {t}", s.j);
        assert!(
            s.s >= prev_s - 1e-15 * p.length().max(1.0),
            "s not monotone at {t}"
        );
        assert!(s.s <= p.length() * (1.0 + 1e-12) + 1e-15);
        prev_s = s.s;
    }
    // Derivatives by central differences.
    let h = total * 1e-6;
    for k in 1..200 {
        let t = total * k as f64 / 200.0;
        let (a, b, c) = (p.sample(t - h), p.sample(t), p.sample(t + h));
        let scale_v = l.v_max.max(1e-300);
        assert!(((c.s - a.s) / (2.0 * h) - b.v).abs() <= 1e-4 * scale_v);
        assert!(((c.v - a.v) / (2.0 * h) - b.a).abs() <= 1e-3 * l.a_max + l.j_max * h);
    }
    // Ends exactly at rest on the target.
    let end = p.sample(total);
    assert_eq!(end.s, p.length());
    assert_eq!((end.v, end.a, end.j), (0.0, 0.0, 0.0));
    let start = p.sample(0.0);
    assert_eq!((start.s, start.v, start.a), (0.0, 0.0, 0.0));
}

/// Case 1 (v and a reached): L = 1 m, v = 1, a = 10, j = 1000.
/// t_j = a/j = 10 ms, t_a = v/a - a/j = 90 ms, t_acc = 110 ms, t_v = L/v - t_acc = 0.89 s,
/// T = L/v + t_acc = 1.11 s.
#[test]
fn hand_case_v_and_a_reached() {
    let l = lim(1.0, 10.0, 1000.0);
    let p = Profile::new(1.0, &l).unwrap();
    assert_relative_eq!(p.t_j(), 0.01, epsilon = 1e-15);
    assert_relative_eq!(p.t_a(), 0.09, epsilon = 1e-14);
    assert_relative_eq!(p.t_v(), 0.89, epsilon = 1e-12);
    assert_relative_eq!(p.duration(), 1.11, epsilon = 1e-12);
    assert_relative_eq!(p.v_peak(), 1.0, epsilon = 1e-14);
    assert_relative_eq!(p.a_peak(), 10.0, epsilon = 1e-12);
    check_profile(&p, &l);
}

/// Case 3 (a reached, v not): L = 0.1 m, v = 1, a = 10, j = 1000. Reaching v would need
/// v (v/a + a/j) = 0.11 m > 0.1 m. t_j = 10 ms; L = a (t_j + t_a)(2 t_j + t_a) gives
/// t_a = (sqrt(t_j^2 + 4L/a) - 3 t_j)/2 = (sqrt(0.0401) - 0.03)/2 = 85.1249 ms,
/// v_peak = a (t_j + t_a) = 0.951249 m/s, T = 2 (2 t_j + t_a) = 210.2498 ms, t_v = 0.
#[test]
fn hand_case_a_reached_v_not() {
    let l = lim(1.0, 10.0, 1000.0);
    let p = Profile::new(0.1, &l).unwrap();
    let t_a = (0.0401_f64.sqrt() - 0.03) / 2.0;
    assert_relative_eq!(t_a, 0.085_124_922, epsilon = 1e-9);
    assert_relative_eq!(p.t_j(), 0.01, epsilon = 1e-15);
    assert_relative_eq!(p.t_a(), t_a, epsilon = 1e-14);
    assert!(p.t_v().abs() < 1e-12);
    assert_relative_eq!(p.v_peak(), 10.0 * (0.01 + t_a), epsilon = 1e-12);
    assert_relative_eq!(p.duration(), 2.0 * (0.02 + t_a), epsilon = 1e-12);
    check_profile(&p, &l);
}

/// Case 2 (v reached, a not): L = 1 m, v = 1, a = 10, j = 50: a^2/j = 2 > v, so
/// t_j = sqrt(v/j) = 141.421 ms, t_a = 0, a_peak = sqrt(v j) = 7.0711 m/s^2,
/// T = L/v + 2 t_j = 1.282843 s.
#[test]
fn hand_case_v_reached_a_not() {
    let l = lim(1.0, 10.0, 50.0);
    let p = Profile::new(1.0, &l).unwrap();
    let tj = 0.02_f64.sqrt();
    assert_relative_eq!(p.t_j(), tj, epsilon = 1e-15);
    assert_eq!(p.t_a(), 0.0);
    assert_relative_eq!(p.a_peak(), 50.0_f64.sqrt(), epsilon = 1e-12);
    assert_relative_eq!(p.t_v(), 1.0 - 2.0 * tj, epsilon = 1e-12);
    assert_relative_eq!(p.duration(), 1.0 + 2.0 * tj, epsilon = 1e-12);
    check_profile(&p, &l);
}

/// Case 4 (neither reached): L = 1 mm, v = 1, a = 10, j = 1000: L < 2 a^3/j^2 = 2 mm, so
/// t_j = cbrt(L / 2j) = cbrt(5e-7) = 7.93701 ms, T = 4 t_j, a_peak = j t_j = 7.937 m/s^2,
/// v_peak = j t_j^2 = 0.0630 m/s.
#[test]
fn hand_case_nothing_reached() {
    let l = lim(1.0, 10.0, 1000.0);
    let p = Profile::new(0.001, &l).unwrap();
    let tj = 5.0e-7_f64.cbrt();
    assert_relative_eq!(tj, 0.007_937_005, epsilon = 1e-9);
    assert_relative_eq!(p.t_j(), tj, epsilon = 1e-15);
    assert_eq!(p.t_a(), 0.0);
    assert!(p.t_v().abs() < 1e-12);
    assert_relative_eq!(p.duration(), 4.0 * tj, epsilon = 1e-14);
    assert_relative_eq!(p.v_peak(), 1000.0 * tj * tj, epsilon = 1e-12);
    check_profile(&p, &l);
}

#[test]
fn zero_length_profile_is_instant() {
    let p = Profile::new(0.0, &lim(1.0, 1.0, 1.0)).unwrap();
    assert_eq!(p.duration(), 0.0);
    assert_eq!(p.sample(1.0).s, 0.0);
}

/// The paper's x (100 mm) and y (150 mm) motions at 1..5 g with [`motion::paper_limits`]:
/// acceleration times match by construction, durations within 2.5 ms.
#[test]
fn paper_durations_are_reproduced() {
    println!(
        "g | x: paper  ours  diff [ms] | y: paper  ours  diff | t_acc paper ours | v_max j_max a_peak/g"
    );
    for g in 1..=5u8 {
        let l = motion::paper_limits(g).unwrap();
        let k = usize::from(g - 1);
        assert_relative_eq!(l.a_max, f64::from(g) * PAPER_G);
        let x = Trajectory::line(
            Vector2::new(0.172_132, 0.0),
            Vector2::new(0.272_132, 0.0),
            &l,
        )
        .unwrap();
        let y = Trajectory::line(
            Vector2::new(0.222_132, -0.075),
            Vector2::new(0.222_132, 0.075),
            &l,
        )
        .unwrap();
        let (px, _) = x.segment_profile(0).unwrap();
        let (py, _) = y.segment_profile(0).unwrap();
        let dx = (x.duration() - PAPER_X_DURATIONS[k]) * 1e3;
        let dy = (y.duration() - PAPER_Y_DURATIONS[k]) * 1e3;
        println!(
            "{g} | {:.0} {:.2} {dx:+.2} | {:.0} {:.2} {dy:+.2} | {:.0} {:.2} | {:.4} {:.0} {:.3}",
            PAPER_X_DURATIONS[k] * 1e3,
            x.duration() * 1e3,
            PAPER_Y_DURATIONS[k] * 1e3,
            y.duration() * 1e3,
            PAPER_ACCEL_TIMES[k] * 1e3,
            px.accel_time() * 1e3,
            l.v_max,
            l.j_max,
            px.a_peak() / PAPER_G,
        );
        assert!(
            dx.abs() < 2.5 && dy.abs() < 2.5,
            "g = {g}: {dx} ms, {dy} ms"
        );
        assert_relative_eq!(px.accel_time(), PAPER_ACCEL_TIMES[k], epsilon = 1e-12);
        assert_relative_eq!(py.accel_time(), PAPER_ACCEL_TIMES[k], epsilon = 1e-12);
        assert_relative_eq!(px.v_peak(), l.v_max, epsilon = 1e-12);
        assert!(px.a_peak() <= l.a_max * (1.0 + 1e-12));
        check_profile(px, &l);
        check_profile(py, &l);
    }
    assert_eq!(
        motion::paper_limits(0),
        Err(BuildError::UnknownGLevel { g_level: 0 })
    );
    assert_eq!(
        motion::paper_limits(6),
        Err(BuildError::UnknownGLevel { g_level: 6 })
    );
}

#[test]
fn triangle_stops_at_corners_and_ends_exactly() {
    let l = motion::paper_limits(3).unwrap();
    let pts = [
        Vector2::new(0.172_132, -0.075),
        Vector2::new(0.272_132, 0.0),
        Vector2::new(0.172_132, 0.075),
        Vector2::new(0.172_132, -0.075),
    ];
    let tr = Trajectory::polyline(&pts, &l).unwrap();
    assert_eq!(tr.segment_count(), 3);
    for i in 0..3 {
        let (p, t0) = tr.segment_profile(i).unwrap();
        let s = tr.sample(t0).unwrap();
        assert_relative_eq!(s.position, pts[i], epsilon = 1e-15);
        assert_eq!(s.velocity.norm(), 0.0);
        let e = tr.sample(t0 + p.duration()).unwrap();
        assert_relative_eq!(e.position, pts[i + 1], epsilon = 1e-15);
        assert!(e.velocity.norm() < 1e-12);
    }
    let end = tr.sample(tr.duration()).unwrap();
    assert_eq!(end.position, pts[3]);
    assert_eq!(end.segment, 2);
    assert_relative_eq!(end.path.s, tr.path_length(), epsilon = 1e-15);
    let side = (pts[1] - pts[0]).norm() + (pts[2] - pts[1]).norm() + 0.15;
    assert_relative_eq!(tr.path_length(), side, epsilon = 1e-15);
}

#[test]
fn ticks_at_2khz() {
    let l = motion::paper_limits(5).unwrap();
    let tr = Trajectory::line(Vector3::zeros(), Vector3::new(0.06, 0.08, 0.0), &l).unwrap();
    let states: Vec<_> = tr.ticks(motion::DEFAULT_RATE_HZ).unwrap().collect();
    let n = (tr.duration() * 2000.0).ceil() as usize + 1;
    assert_eq!(states.len(), n);
    assert_eq!(states[0].position, Vector3::zeros());
    assert_eq!(states[n - 1].position, Vector3::new(0.06, 0.08, 0.0));
    assert_eq!(states[n - 1].t, tr.duration());
    for (k, s) in states.iter().enumerate().take(n - 1) {
        assert_eq!(s.t, k as f64 / 2000.0);
        assert_eq!(*s, tr.sample(s.t).unwrap());
        assert!(s.velocity.norm() <= l.v_max * (1.0 + 1e-12));
        assert!(s.acceleration.norm() <= l.a_max * (1.0 + 1e-12));
        // Direction of motion is the line's.
        let dir = Vector3::new(0.6, 0.8, 0.0);
        assert_relative_eq!(s.velocity, dir * s.path.v, epsilon = 1e-15);
    }
    // Step by step gives the same, and the cursor reports its progress.
    let mut c = tr.ticks(2000.0).unwrap();
    assert_eq!(c.len(), n);
    let first = c.step().unwrap();
    assert_eq!(first, states[0]);
    assert_eq!(c.remaining(), n - 1);
    let rest: Vec<_> = c.by_ref().collect();
    assert_eq!(rest.len(), n - 1);
    assert!(c.is_finished());
    assert!(c.step().is_none());
    // A duration of exactly k ticks: k + 1 samples, no duplicate at the end.
    let one = Trajectory::line(
        SVector::<f64, 1>::new(0.0),
        SVector::<f64, 1>::new(1.0),
        &lim(1.0, 10.0, 1000.0),
    )
    .unwrap();
    assert_relative_eq!(one.duration(), 1.11, epsilon = 1e-12);
    assert_eq!(one.ticks(100.0).unwrap().count(), 112);
}

#[test]
fn validation_errors() {
    let p0 = Vector2::new(0.0, 0.0);
    let p1 = Vector2::new(0.1, 0.0);
    for (v, a, j, what, bad) in [
        (0.0, 1.0, 1.0, "v_max", 0.0),
        (-1.0, 1.0, 1.0, "v_max", -1.0),
        (1.0, f64::INFINITY, 1.0, "a_max", f64::INFINITY),
        (1.0, 1.0, -0.0, "j_max", -0.0),
    ] {
        assert_eq!(
            Limits::new(v, a, j),
            Err(BuildError::InvalidParameter {
                what,
                value: bad,
                expected: "finite and > 0 (not sub-normal)"
            })
        );
        let raw = Limits {
            v_max: v,
            a_max: a,
            j_max: j,
        };
        assert!(matches!(
            Trajectory::line(p0, p1, &raw),
            Err(BuildError::InvalidParameter { .. })
        ));
    }
    assert!(matches!(
        Limits::new(1.0, f64::NAN, 1.0),
        Err(BuildError::InvalidParameter { what: "a_max", .. })
    ));
    let l = lim(1.0, 10.0, 100.0);
    assert_eq!(
        Trajectory::line(p0, Vector2::new(0.1, f64::NAN), &l),
        Err(BuildError::NonFinite {
            what: "points (flattened, N per point)",
            // Point 1, axis 1, N = 2 coordinates per point.
            index: 3
        })
    );
    assert_eq!(
        Trajectory::<2>::polyline(&[p0], &l),
        Err(BuildError::TooFew {
            what: "points",
            needed: 2,
            got: 1
        })
    );
    assert_eq!(
        Trajectory::<2>::polyline(&[], &l),
        Err(BuildError::TooFew {
            what: "points",
            needed: 2,
            got: 0
        })
    );
    let many = vec![p1; MAX_POINTS + 1];
    assert_eq!(
        Trajectory::polyline(&many, &l),
        Err(BuildError::Capacity {
            what: "points",
            capacity: MAX_POINTS,
            got: MAX_POINTS + 1
        })
    );
    let full: Vec<_> = (0..MAX_POINTS)
        .map(|i| Vector2::new(i as f64 * 0.01, 0.0))
        .collect();
    assert_eq!(
        Trajectory::polyline(&full, &l).unwrap().segment_count(),
        MAX_POINTS - 1
    );
    assert_eq!(
        Profile::new(-1.0, &l),
        Err(BuildError::InvalidParameter {
            what: "profile length",
            value: -1.0,
            expected: "finite and >= 0 (m)"
        })
    );
    let tr = Trajectory::line(p0, p1, &l).unwrap();
    assert!(matches!(
        tr.sample(f64::NAN),
        Err(TickError::NonFinite {
            what: "t",
            index: 0
        })
    ));
    for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            tr.ticks(r),
            Err(TickError::InvalidArgument {
                what: "rate_hz",
                ..
            })
        ));
    }
    // Before the start and after the end: at rest.
    assert_eq!(tr.sample(-1.0).unwrap().position, p0);
    assert_eq!(tr.sample(1e6).unwrap().position, p1);
}

#[test]
fn replan_line_refuses_as_line_does_and_leaves_the_plan() {
    let l = lim(1.2, 25.0, 600.0);
    let mut tr = Trajectory::line(Vector2::new(0.0, 0.0), Vector2::new(0.1, 0.0), &l).unwrap();
    let kept = tr.clone();
    let bad = Limits { v_max: -1.0, ..l };
    for (s, e, lm) in [
        (Vector2::new(0.0, f64::NAN), Vector2::new(0.1, 0.0), l),
        (Vector2::new(0.0, 0.0), Vector2::new(f64::INFINITY, 0.0), l),
        (Vector2::new(0.0, 0.0), Vector2::new(0.2, 0.0), bad),
        // Equal points validate the limits too (no profile is solved).
        (Vector2::new(0.3, 0.0), Vector2::new(0.3, 0.0), bad),
    ] {
        let want = Trajectory::line(s, e, &lm).unwrap_err();
        assert_eq!(tr.replan_line(s, e, &lm).unwrap_err(), want);
        assert_eq!(tr, kept);
    }
    assert!(matches!(
        tr.replan_line(Vector2::new(0.0, 0.0), Vector2::new(0.0, f64::NAN), &l),
        Err(BuildError::NonFinite { index: 3, .. })
    ));
}

#[test]
fn zero_length_segments_are_skipped() {
    let l = lim(1.0, 10.0, 100.0);
    let a = Vector2::new(0.0, 0.0);
    let b = Vector2::new(0.1, 0.0);
    let c = Vector2::new(0.1, 0.1);
    let with = Trajectory::polyline(&[a, a, b, b, b, c, c], &l).unwrap();
    let without = Trajectory::polyline(&[a, b, c], &l).unwrap();
    assert_eq!(with.segment_count(), 2);
    assert_eq!(with.duration(), without.duration());
    for k in 0..=50 {
        let t = with.duration() * k as f64 / 50.0;
        assert_eq!(with.sample(t).unwrap(), without.sample(t).unwrap());
    }
    // All points equal: a zero-duration trajectory that stays put.
    let still = Trajectory::polyline(&[b, b, b], &l).unwrap();
    assert_eq!(still.segment_count(), 0);
    assert_eq!(still.duration(), 0.0);
    assert_eq!(still.sample(0.0).unwrap().position, b);
    assert_eq!(still.ticks(2000.0).unwrap().count(), 1);
}

/// The closed form solved from scratch for one length, written out as the module docs give
/// it: `(t_j, t_a, t_v)`.
fn closed_form(length: f64, v: f64, a: f64, j: f64) -> (f64, f64, f64) {
    let (mut t_j, mut t_a) = if a * a / j <= v {
        (a / j, v / a - a / j)
    } else {
        ((v / j).sqrt(), 0.0)
    };
    if length < j * t_j * (t_j + t_a) * (2.0 * t_j + t_a) {
        if length >= 2.0 * a * a * a / (j * j) {
            t_j = a / j;
            t_a = 0.5 * ((t_j * t_j + 4.0 * length / a).sqrt() - 3.0 * t_j);
        } else {
            t_j = (length / (2.0 * j)).cbrt();
            t_a = 0.0;
        }
    }
    let t_a = t_a.max(0.0);
    let ap = j * t_j;
    let s1 = j * t_j * t_j * t_j / 6.0;
    let v1 = 0.5 * j * t_j * t_j;
    let s2 = s1 + v1 * t_a + 0.5 * ap * t_a * t_a;
    let v2 = v1 + ap * t_a;
    let s3 = s2 + v2 * t_j + 0.5 * ap * t_j * t_j - j * t_j * t_j * t_j / 6.0;
    let v3 = v2 + ap * t_j - 0.5 * j * t_j * t_j;
    let t_v = if v3 > 0.0 {
        ((length - 2.0 * s3) / v3).max(0.0)
    } else {
        0.0
    };
    (t_j, t_a, t_v)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Limits prepared once give, for every length (all four cases of the closed form), the
    /// profile solved from scratch, bit for bit.
    #[test]
    fn prepared_limits_profile_is_the_closed_form_bit_for_bit(
        lengths in prop::collection::vec(0.0f64..2.0, 1..16),
        v in 0.01f64..5.0,
        a in 0.1f64..100.0,
        j in 1.0f64..1e5,
    ) {
        let l = lim(v, a, j);
        let prepared = PreparedLimits::new(&l).unwrap();
        prop_assert_eq!(prepared.limits(), &l);
        // Short lengths too: cases 3 and 4 need a length below the cruise distance.
        for length in lengths.iter().flat_map(|x| [*x, x * 1e-3, x * 1e-6]) {
            let p = prepared.profile(length).unwrap();
            let (t_j, t_a, t_v) = closed_form(length, v, a, j);
            prop_assert_eq!(
                [p.t_j(), p.t_a(), p.t_v()].map(f64::to_bits),
                [t_j, t_a, t_v].map(f64::to_bits),
                "length {}", length
            );
            prop_assert_eq!(p, Profile::new(length, &l).unwrap());
        }
    }

    #[test]
    fn random_profiles_respect_limits(
        length in 1e-6f64..2.0,
        v in 0.01f64..5.0,
        a in 0.1f64..100.0,
        j in 1.0f64..1e5,
    ) {
        let l = lim(v, a, j);
        let p = Profile::new(length, &l).unwrap();
        check_profile(&p, &l);
        // Time-optimality sanity: never faster than the limits allow separately.
        prop_assert!(p.duration() >= length / v * (1.0 - 1e-12));
        prop_assert!(p.duration() >= 2.0 * (length / a).sqrt() * (1.0 - 1e-12));
        prop_assert!(p.duration() >= 2.0 * (4.0 * length / j).cbrt() * (1.0 - 1e-9));
    }

    /// Re-planning in place is `line` bit for bit, whatever the trajectory held before
    /// (a polyline of several segments, or a rest), including equal points.
    #[test]
    fn replan_line_equals_line(
        before in prop::collection::vec(prop::array::uniform3(-0.5f64..0.5), 2..6),
        start in prop::array::uniform3(-0.5f64..0.5),
        end in prop::array::uniform3(-0.5f64..0.5),
        same in any::<bool>(),
        v in 0.05f64..2.0,
        a in 1.0f64..50.0,
        j in 10.0f64..1e4,
    ) {
        let l = lim(v, a, j);
        let before: Vec<Vector3<f64>> = before.iter().map(|p| Vector3::from(*p)).collect();
        let mut tr = Trajectory::polyline(&before, &lim(1.0, 10.0, 100.0)).unwrap();
        let (s, e) = (Vector3::from(start), if same { Vector3::from(start) } else { Vector3::from(end) });
        tr.replan_line(s, e, &l).unwrap();
        prop_assert_eq!(&tr, &Trajectory::line(s, e, &l).unwrap());
        let mut again = Trajectory::polyline(&before, &lim(1.0, 10.0, 100.0)).unwrap();
        again.replan_line_with(s, e, &PreparedLimits::new(&l).unwrap()).unwrap();
        prop_assert_eq!(&again, &tr);
    }

    #[test]
    fn random_polylines_end_on_target(
        pts in prop::collection::vec(prop::array::uniform3(-0.5f64..0.5), 2..8),
        v in 0.05f64..2.0,
        a in 1.0f64..50.0,
        j in 10.0f64..1e4,
    ) {
        let l = lim(v, a, j);
        let pts: Vec<Vector3<f64>> = pts.iter().map(|p| Vector3::from(*p)).collect();
        let tr = Trajectory::polyline(&pts, &l).unwrap();
        let last = *pts.last().unwrap();
        prop_assert_eq!(tr.sample(tr.duration()).unwrap().position, last);
        let mut prev = tr.sample(0.0).unwrap();
        prop_assert_eq!(prev.position, pts[0]);
        for s in tr.ticks(500.0).unwrap().skip(1) {
            prop_assert!(s.velocity.norm() <= v * (1.0 + 1e-9));
            prop_assert!(s.acceleration.norm() <= a * (1.0 + 1e-9));
            prop_assert!(s.jerk.norm() <= j * (1.0 + 1e-9));
            // Positions move at most v_max * dt between ticks.
            prop_assert!((s.position - prev.position).norm() <= v * (s.t - prev.t) * (1.0 + 1e-9) + 1e-15);
            prev = s;
        }
        prop_assert_eq!(prev.position, last);
        prop_assert_eq!(prev.velocity.norm(), 0.0);
    }
}
