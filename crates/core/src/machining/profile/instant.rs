//! The instantaneous wrench of a cut at one spindle angle (see the parent module).

use nalgebra::ComplexField;

use super::{
    Cut, EdgeWrench, MAX_LAG_TURNS, Profile, chip, element_force, nodes, position, push, sort,
};
use crate::error::TickError;
use crate::machining::cutting::Coefficients;

/// Samples per piece searched for a zero of the chip along the profile.
const CHIP_SAMPLES: usize = 16;

/// The wrench \[N, N m\] about the tool tip, tool frame, of `cut` on the cutter `profile` with
/// edge 0 at `angle` \[rad\] at the tip (clockwise from +y). Along each flute the edge lags
/// `z tan(helix) / R` at height `z`; the profile is split where a flute enters or leaves a
/// band's immersion, at the corner's end and where the chip changes sign (found by bisection
/// on 16 samples per piece), and each piece integrated by 8-point Gauss-Legendre.
///
/// [`TickError`]s of [`Cut::validate`], [`TickError::NonFinite`] for the angle,
/// [`TickError::Budget`] for a band spanning more than [`MAX_LAG_TURNS`] helix turns,
/// [`TickError::NonFiniteOutput`].
pub fn force(
    coefficients: &Coefficients,
    profile: &Profile,
    cut: &Cut<'_>,
    angle: f64,
) -> Result<EdgeWrench, TickError> {
    cut.validate()?;
    crate::error::check_finite("angle", &[angle])?;
    let tau = core::f64::consts::TAU;
    let lead = profile.lead();
    for b in cut.bands {
        let turns = lead * (b.top - b.bottom) / tau;
        if turns > MAX_LAG_TURNS {
            return Err(TickError::Budget {
                what: "helix turns one band spans",
                budget: "MAX_LAG_TURNS",
                limit: MAX_LAG_TURNS,
                requested: turns,
            });
        }
    }
    let pitch = tau / f64::from(profile.flutes());
    let mut total = EdgeWrench::default();
    for band in cut.bands {
        for j in 0..profile.flutes() {
            let phi0 = angle + f64::from(j) * pitch;
            if lead == 0.0 {
                let inside = (phi0 - band.entry).rem_euclid_free(tau) + band.entry <= band.exit;
                if inside {
                    span(
                        coefficients,
                        profile,
                        cut,
                        phi0,
                        band.bottom,
                        band.top,
                        &mut total,
                    );
                }
                continue;
            }
            // phi0 - lead z - 2 pi k in [entry, exit]  <=>  z in [lo_k, hi_k].
            let k_min = ComplexField::ceil((phi0 - lead * band.top - band.exit) / tau);
            let k_max = ComplexField::floor((phi0 - lead * band.bottom - band.entry) / tau);
            let mut k = k_min;
            while k <= k_max {
                let lo = (phi0 - tau * k - band.exit) / lead;
                let hi = (phi0 - tau * k - band.entry) / lead;
                let (z0, z1) = (lo.max(band.bottom), hi.min(band.top));
                if z1 > z0 {
                    span(coefficients, profile, cut, phi0, z0, z1, &mut total);
                }
                k += 1.0;
            }
        }
    }
    total.check("instantaneous cutter wrench")
}

/// `x mod m` in `[0, m)` without std.
trait RemEuclid {
    fn rem_euclid_free(self, m: f64) -> f64;
}

impl RemEuclid for f64 {
    fn rem_euclid_free(self, m: f64) -> f64 {
        let r = self % m;
        if r < 0.0 { r + m } else { r }
    }
}

/// Adds one flute's wrench over heights `z0..z1` (inside its band's immersion) to `total`.
fn span(
    k: &Coefficients,
    profile: &Profile,
    cut: &Cut<'_>,
    phi0: f64,
    z0: f64,
    z1: f64,
    total: &mut EdgeWrench,
) {
    let (s0, s1) = (profile.arc_length(z0), profile.arc_length(z1));
    let lead = profile.lead();
    let feed = &cut.feed;
    let h = |s: f64| {
        let e = profile.element(s);
        chip(feed, &e, phi0 - lead * e.z)
    };
    let mut corner = [0.0; 1];
    let mut nc = 0;
    push(&mut corner, &mut nc, profile.round(), s0, s1);
    let mut a = s0;
    for i in 0..=nc {
        let b = corner.get(i).copied().filter(|_| i < nc).unwrap_or(s1);
        // The chip's sign changes along [a, b]: bisected between samples.
        let mut zeros = [0.0; CHIP_SAMPLES];
        let mut nz = 0;
        let step = (b - a) / CHIP_SAMPLES as f64;
        let mut prev = h(a);
        for m in 1..=CHIP_SAMPLES {
            let x = if m == CHIP_SAMPLES {
                b
            } else {
                a + step * m as f64
            };
            let hx = h(x);
            if (prev < 0.0) != (hx < 0.0) {
                let (mut l, mut r) = (x - step, x);
                for _ in 0..80 {
                    let mid = 0.5 * (l + r);
                    if (h(mid) < 0.0) == (hx < 0.0) {
                        r = mid;
                    } else {
                        l = mid;
                    }
                }
                push(&mut zeros, &mut nz, 0.5 * (l + r), a, b);
            }
            prev = hx;
        }
        sort(&mut zeros, nz);
        let mut p = a;
        for q_i in 0..=nz {
            let q = zeros.get(q_i).copied().filter(|_| q_i < nz).unwrap_or(b);
            if q > p && h(0.5 * (p + q)) >= 0.0 {
                for (s, w) in nodes(p, q, false) {
                    let e = profile.element(s);
                    let phi = phi0 - lead * e.z;
                    let hh = chip(feed, &e, phi).max(0.0);
                    let f = element_force(k, &e, phi, hh) * w;
                    total.force += f;
                    total.moment += position(&e, phi).cross(&f);
                }
            }
            p = q;
        }
        a = b;
    }
}
