//! The revolution's mean wrench of a cut: closed form in the immersion, Gauss-Legendre along
//! the profile (see the parent module).

use nalgebra::{ComplexField, RealField, Vector3};

use super::{Band, Cut, EdgeWrench, Element, Profile, chip, nodes, push, sort};
use crate::error::TickError;
use crate::machining::cutting::Coefficients;

/// The integrals of `[1, sin, cos, sin^2, sin cos, cos^2]` over `[a, b]`.
fn basis(a: f64, b: f64) -> [f64; 6] {
    let (sa, ca) = ComplexField::sin_cos(a);
    let (sb, cb) = ComplexField::sin_cos(b);
    let (s2a, s2b) = (ComplexField::sin(2.0 * a), ComplexField::sin(2.0 * b));
    let w = b - a;
    [
        w,
        ca - cb,
        sb - sa,
        0.5 * w - 0.25 * (s2b - s2a),
        0.5 * (sb * sb - sa * sa),
        0.5 * w + 0.25 * (s2b - s2a),
    ]
}

/// `l1 sin + l2 cos + l0` integrated against 1, sin and cos with the basis `j`.
fn moments(l: [f64; 3], j: &[f64; 6]) -> [f64; 3] {
    let [l1, l2, l0] = l;
    let [j1, js, jc, jss, jsc, jcc] = *j;
    [
        l1 * js + l2 * jc + l0 * j1,
        l1 * jss + l2 * jsc + l0 * js,
        l1 * jsc + l2 * jcc + l0 * jc,
    ]
}

/// The wrench per metre of profile of one element integrated over the immersion
/// `entry..exit` where its chip is `>= 0`, tool frame (not yet times `N / 2 pi`).
fn element(k: &Coefficients, feed: &Vector3<f64>, e: &Element, band: &Band) -> EdgeWrench {
    let (p, q, c0) = (e.sin * feed.x, e.sin * feed.y, e.cos * feed.z);
    // h = p sin + q cos - c0 = m sin(phi + delta) - c0: its zeros split the immersion.
    let m = ComplexField::sqrt(p * p + q * q);
    let mut cuts = [0.0; 12];
    let mut n = 0;
    if m > 0.0 && ComplexField::abs(c0) < m {
        let delta = RealField::atan2(q, p);
        let r = ComplexField::asin(c0 / m);
        let tau = core::f64::consts::TAU;
        for turn in -1..=3 {
            let base = f64::from(turn) * tau - delta;
            push(&mut cuts, &mut n, base + r, band.entry, band.exit);
            push(
                &mut cuts,
                &mut n,
                base + core::f64::consts::PI - r,
                band.entry,
                band.exit,
            );
        }
    }
    sort(&mut cuts, n);
    let lin = |kc: f64, ke: f64| [kc * p, kc * q, ke - kc * c0];
    let kt = lin(k.k_tc, k.k_te);
    let kr = lin(k.k_rc, k.k_re);
    let ka = lin(k.k_ac, k.k_ae);
    let ar: [f64; 3] = core::array::from_fn(|i| {
        -e.sin * kr.get(i).copied().unwrap_or(0.0) + e.cos * ka.get(i).copied().unwrap_or(0.0)
    });
    let az: [f64; 3] = core::array::from_fn(|i| {
        e.cos * kr.get(i).copied().unwrap_or(0.0) + e.sin * ka.get(i).copied().unwrap_or(0.0)
    });
    let mut out = EdgeWrench::default();
    let mut a = band.entry;
    for i in 0..=n {
        let b = cuts.get(i).copied().filter(|_| i < n).unwrap_or(band.exit);
        if b > a && chip(feed, e, 0.5 * (a + b)) >= 0.0 {
            let j = basis(a, b);
            let [t1, ts, tc] = moments(kt, &j);
            let [_, rs, rc] = moments(ar, &j);
            let [z1, zs, zc] = moments(az, &j);
            let f = Vector3::new(-tc + rs, ts + rc, z1);
            out.force += f;
            out.moment += Vector3::new(
                e.radius * zc - e.z * f.y,
                e.z * f.x - e.radius * zs,
                e.radius * t1,
            );
        }
        a = b;
    }
    out
}

/// How a piece of the profile is graded (see [`super::nodes`]).
#[derive(Clone, Copy, PartialEq)]
enum Grade {
    None,
    Start,
    End,
}

/// The wrench \[N, N m\] about the tool tip, tool frame, of `cut` on the cutter `profile`,
/// averaged over one revolution (`N / 2 pi` times the integral over the immersion and the
/// profile): what the robot's structure feels at spindle speeds far above its lowest
/// eigenfrequency. For a flat end mill with one band from the tip and the feed across the
/// axis it is [`crate::machining::cutting::average`] and
/// [`crate::machining::cutting::average_torque`] to rounding.
///
/// [`TickError`]s of [`Cut::validate`], and [`TickError::NonFiniteOutput`].
pub fn average(
    coefficients: &Coefficients,
    profile: &Profile,
    cut: &Cut<'_>,
) -> Result<EdgeWrench, TickError> {
    cut.validate()?;
    let feed = &cut.feed;
    // Where the chip's zeros meet (|c0| = m): tan(kappa) = |f_z| / |f_xy|; and where a zero
    // crosses an angle phi: tan(kappa) = f_z / (f_x sin phi + f_y cos phi).
    let across = ComplexField::sqrt(feed.x * feed.x + feed.y * feed.y);
    let tangency = (feed.z != 0.0 && across > 0.0)
        .then(|| RealField::atan2(ComplexField::abs(feed.z), across))
        .and_then(|k| profile.arc_at(k));
    let crossing = |phi: f64| {
        let (s, c) = ComplexField::sin_cos(phi);
        let g = feed.x * s + feed.y * c;
        (g != 0.0 && feed.z / g > 0.0)
            .then(|| ComplexField::atan(feed.z / g))
            .and_then(|k| profile.arc_at(k))
    };
    let mut total = EdgeWrench::default();
    for band in cut.bands {
        let (s0, s1) = (
            profile.arc_length(band.bottom),
            profile.arc_length(band.top),
        );
        let mut cuts = [0.0; 4];
        let mut n = 0;
        for x in [
            Some(profile.round()),
            tangency,
            crossing(band.entry),
            crossing(band.exit),
        ]
        .into_iter()
        .flatten()
        {
            push(&mut cuts, &mut n, x, s0, s1);
        }
        sort(&mut cuts, n);
        let mut a = s0;
        for i in 0..=n {
            let b = cuts.get(i).copied().filter(|_| i < n).unwrap_or(s1);
            let grade = match tangency {
                Some(t) if t == a => Grade::Start,
                Some(t) if t == b => Grade::End,
                _ => Grade::None,
            };
            for (s, w) in piece(a, b, grade) {
                let e = profile.element(s);
                let w_e = element(coefficients, feed, &e, band);
                total.force += w_e.force * w;
                total.moment += w_e.moment * w;
            }
            a = b;
        }
    }
    let scale = f64::from(profile.flutes()) / core::f64::consts::TAU;
    EdgeWrench {
        force: total.force * scale,
        moment: total.moment * scale,
    }
    .check("average cutter wrench")
}

/// The nodes of one piece `[a, b]`, graded towards the end that `grade` names.
fn piece(a: f64, b: f64, grade: Grade) -> impl Iterator<Item = (f64, f64)> {
    let (start, end, graded) = match grade {
        Grade::End => (b, a, true),
        Grade::Start => (a, b, true),
        Grade::None => (a, b, false),
    };
    // Graded from the end: the same rule run backwards (the weight's sign flips with it).
    nodes(start, end, graded).map(move |(s, w)| (s, if grade == Grade::End { -w } else { w }))
}
