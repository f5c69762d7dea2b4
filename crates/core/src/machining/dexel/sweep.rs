//! One straight sweep of the tool through the three grids (see the parent module): each ray
//! against the swept solid, and the subtraction of the interval it finds from the ray's
//! material.

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector3};

use super::{DexelRemoval, DexelTool, Dexels, MAX_INTERVALS, across, at, count};
use crate::error::TickError;

impl Dexels {
    /// One straight sweep with a fixed axis.
    pub(super) fn sweep(
        &mut self,
        tool: &DexelTool,
        from: &Vector3<f64>,
        to: &Vector3<f64>,
        axis: &Vector3<f64>,
    ) -> Result<DexelRemoval, TickError> {
        // The swept solid's box: both tools' axis segments, widened by the radius.
        let (tops, r) = (axis * tool.length, tool.radius);
        let mut lo = from.inf(to).inf(&(from + tops)).inf(&(to + tops));
        let mut hi = from.sup(to).sup(&(from + tops)).sup(&(to + tops));
        lo.add_scalar_mut(-r);
        hi.add_scalar_mut(r);
        let mut out = DexelRemoval::default();
        let area = self.cell * self.cell;
        for d in 0..3 {
            let (u, v) = across(d);
            let range = |k: usize| {
                let x0 = (at(&lo, k) - at(&self.min, k)) / self.cell - 0.5;
                let x1 = (at(&hi, k) - at(&self.min, k)) / self.cell - 0.5;
                let n = count(&self.n, k);
                let a = ComplexField::ceil(x0).max(0.0) as usize;
                let b = (ComplexField::floor(x1) + 1.0).clamp(0.0, n as f64) as usize;
                a..b.max(a)
            };
            let (ru, rv) = (range(u), range(v));
            let nv = count(&self.n, v);
            let (dlo, dhi) = (at(&lo, d), at(&hi, d));
            for i in ru {
                for j in rv.clone() {
                    let mut origin = self.min;
                    if let Some(x) = origin.get_mut(u) {
                        *x += (i as f64 + 0.5) * self.cell;
                    }
                    if let Some(x) = origin.get_mut(v) {
                        *x += (j as f64 + 0.5) * self.cell;
                    }
                    if let Some(x) = origin.get_mut(d) {
                        *x = 0.0;
                    }
                    let Some((a, b)) = hit(tool, &origin, d, from, to, axis, dlo, dhi) else {
                        continue;
                    };
                    let Some(ray) = self.rays.get_mut(d).and_then(|g| g.get_mut(i * nv + j)) else {
                        continue;
                    };
                    let before = ray.len();
                    let removed = subtract(ray, a, b, self.intervals < MAX_INTERVALS)?;
                    if removed > 0.0 {
                        out.rays += 1;
                        if d == 2 {
                            out.volume += removed * area;
                        }
                    }
                    self.intervals = self.intervals + ray.len() - before;
                }
            }
        }
        Ok(out)
    }
}

/// Golden-section iterations along the ray (the bracket shrinks by 0.618 each: 5e-8 of it
/// after 35; only the sign of the minimum is read from it) and along the move (28: 1.4e-6
/// of the move; the minimum's error is second order in it, the functions being smooth on
/// their slab).
const GOLDEN: usize = 35;
const GOLDEN_MOVE: usize = 28;
/// Most steps of the Illinois search for an interval's end (it stops at 1e-13 m; convergence
/// is superlinear, a dozen steps on these convex functions).
const BISECT: usize = 80;

/// Removes `[a, b]` from a ray's sorted intervals; the length removed. Splitting an interval
/// in two needs `room` ([`TickError::Budget`] otherwise).
pub(super) fn subtract(
    ray: &mut Vec<(f64, f64)>,
    a: f64,
    b: f64,
    room: bool,
) -> Result<f64, TickError> {
    let mut removed = 0.0;
    let mut k = 0;
    while let Some(&(lo, hi)) = ray.get(k) {
        if hi <= a || lo >= b {
            k += 1;
            continue;
        }
        removed += hi.min(b) - lo.max(a);
        match (lo < a, hi > b) {
            (true, true) => {
                if !room {
                    return Err(TickError::Budget {
                        what: "dexel intervals",
                        budget: "MAX_INTERVALS",
                        limit: MAX_INTERVALS as f64,
                        requested: (MAX_INTERVALS + 1) as f64,
                    });
                }
                if let Some(x) = ray.get_mut(k) {
                    *x = (lo, a);
                }
                ray.insert(k + 1, (b, hi));
                return Ok(removed);
            }
            (true, false) => {
                if let Some(x) = ray.get_mut(k) {
                    *x = (lo, a);
                }
                k += 1;
            }
            (false, true) => {
                if let Some(x) = ray.get_mut(k) {
                    *x = (b, hi);
                }
                return Ok(removed);
            }
            (false, false) => {
                ray.remove(k);
            }
        }
    }
    Ok(removed)
}

/// Golden-section minimum of a convex `f` on `[a, b]`: `(argmin, min)`.
fn golden(a: f64, b: f64, iterations: usize, f: &dyn Fn(f64) -> f64) -> (f64, f64) {
    let best = crate::golden::minimise(a, b, iterations, |x| (x, f(x)), |p| p.1);
    // The ends of the bracket are candidates too (a minimum on the boundary).
    [(a, f(a)), (b, f(b))]
        .into_iter()
        .fold(best, |best, x| if x.1 < best.1 { x } else { best })
}

/// Where along the ray through `origin` (its coordinate `d` free) the tool swept from `from`
/// to `to` with `axis` lies: the interval of the coordinate, within `[lo, hi]`.
#[allow(clippy::too_many_arguments)] // reason: one ray against one sweep, called from one loop
pub(super) fn hit(
    tool: &DexelTool,
    origin: &Vector3<f64>,
    d: usize,
    from: &Vector3<f64>,
    to: &Vector3<f64>,
    axis: &Vector3<f64>,
    lo: f64,
    hi: f64,
) -> Option<(f64, f64)> {
    let ray = RaySweep::new(tool, origin, d, from, to, axis);
    let (t0, t1) = ray.t_range(lo, hi)?;
    let (tm, fm) = golden(t0, t1, GOLDEN, &|t| ray.gap(t));
    if fm.is_nan() || fm > 0.0 {
        return None;
    }
    let a = if ray.gap(t0) <= 0.0 {
        t0
    } else {
        ray.edge(tm, t0)
    };
    let b = if ray.gap(t1) <= 0.0 {
        t1
    } else {
        ray.edge(tm, t1)
    };
    (b > a).then_some((a, b))
}

/// One ray against one straight sweep: the coefficients [`hit`]'s search reads, in plain
/// f64 (this is the inner loop, thousands of evaluations per ray, and nalgebra's small
/// vectors are slow unoptimised). `t` is the ray's coordinate (m), `s` the fraction of the
/// move (0 at `from`, 1 at `to`).
struct RaySweep<'a> {
    tool: &'a DexelTool,
    /// z(t, s) = alpha + beta t - gamma s along the axis (m).
    alpha: f64,
    beta: f64,
    gamma: f64,
    /// The tool's length (m).
    h: f64,
    /// |w|^2 of w = (origin - from) + t e - s step is
    /// q0 + t^2 + s^2 dd + 2 (t qe - s qd - t s ed).
    q0: f64,
    qe: f64,
    qd: f64,
    ed: f64,
    dd: f64,
    /// The tool's corner radius (m).
    corner: f64,
    /// Whether the tool is a ball end (corner = radius).
    ball: bool,
    /// The s^2 coefficient of the squared distance from the axis, dd - gamma^2.
    quad_a: f64,
}

impl<'a> RaySweep<'a> {
    /// The coefficients for the ray through `origin` along coordinate `d`.
    #[inline]
    fn new(
        tool: &'a DexelTool,
        origin: &Vector3<f64>,
        d: usize,
        from: &Vector3<f64>,
        to: &Vector3<f64>,
        axis: &Vector3<f64>,
    ) -> Self {
        let mut e = Vector3::zeros();
        if let Some(x) = e.get_mut(d) {
            *x = 1.0;
        }
        let step = to - from;
        let alpha = (origin - from).dot(axis);
        let beta = e.dot(axis);
        let gamma = step.dot(axis);
        let h = tool.length;
        let o = origin - from;
        let (q0, qe, qd) = (o.norm_squared(), at(&o, d), o.dot(&step));
        let (ed, dd) = (at(&step, d), step.norm_squared());
        // The distance from the axis squared, rho^2(s) = q - z^2 = A s^2 + B s + C at `t`: its
        // minimiser is the minimiser of f wherever it lies on the tool's cylinder (z >= the
        // corner radius, everywhere for a flat end), since there f = rho - R and elsewhere
        // f >= rho - R (the radius is at most R). A ball end is the points within R of the
        // axis segment from the ball's centre up (inside the slab), so the distance to that
        // segment minus R has the same sign as f and its minimum over the move is the smaller
        // of two quadratics' on their stretches (above the centre: rho^2; below: the squared
        // distance to the centre). Only a bull-nose's corner needs the search.
        let corner = tool.corner;
        let ball = (tool.radius - corner).abs() <= 1e-12 * tool.radius;
        let quad_a = dd - gamma * gamma;
        Self {
            tool,
            alpha,
            beta,
            gamma,
            h,
            q0,
            qe,
            qd,
            ed,
            dd,
            corner,
            ball,
            quad_a,
        }
    }

    /// The s-range where 0 <= z <= h at `t`, within [0, 1].
    #[inline]
    fn s_range(&self, t: f64) -> Option<(f64, f64)> {
        let (gamma, h) = (self.gamma, self.h);
        let z0 = self.alpha + self.beta * t;
        let (mut a, mut b) = (0.0f64, 1.0f64);
        if gamma.abs() < 1e-300 {
            return (z0 >= 0.0 && z0 <= h).then_some((a, b));
        }
        // 0 <= z0 - gamma s <= h  <=>  s between (z0 - h) / gamma and z0 / gamma.
        let (p, q) = ((z0 - h) / gamma, z0 / gamma);
        a = a.max(p.min(q));
        b = b.min(p.max(q));
        (a <= b).then_some((a, b))
    }

    /// The signed distance (m) of the point at (t, s) from the tool's surface at its height:
    /// negative inside.
    #[inline]
    fn f(&self, t: f64, s: f64) -> f64 {
        let q =
            self.q0 + t * t + s * s * self.dd + 2.0 * (t * self.qe - s * self.qd - t * s * self.ed);
        let z = self.alpha + self.beta * t - self.gamma * s;
        ComplexField::sqrt((q - z * z).max(0.0)) - self.tool.radius_at(z.clamp(0.0, self.h))
    }

    /// The least over the move of the signed distance from the tool at the ray's `t` (m;
    /// infinite where no part of the move's slab reaches it).
    #[inline]
    fn gap(&self, t: f64) -> f64 {
        match self.s_range(t) {
            Some((a, b)) => {
                let z0 = self.alpha + self.beta * t;
                let quad_b = 2.0 * (-self.qd - t * self.ed) + 2.0 * self.gamma * z0;
                let q_t = self.q0 + t * t + 2.0 * t * self.qe;
                if self.ball {
                    return self.ball_gap(t, (a, b), z0, quad_b, q_t);
                }
                self.corner_gap(t, (a, b), z0, quad_b)
            }
            None => f64::INFINITY,
        }
    }

    /// [`Self::gap`] for a ball end on the move's stretch `(a, b)`: the smaller of the two
    /// quadratics' least (above the ball's centre: the distance from the axis; below: from
    /// the centre), less the radius. `z0` is z at s = 0, `quad_b` the s coefficient of
    /// rho^2, `q_t` |w|^2 at s = 0.
    #[inline]
    fn ball_gap(&self, t: f64, (a, b): (f64, f64), z0: f64, quad_b: f64, q_t: f64) -> f64 {
        let (gamma, corner) = (self.gamma, self.corner);
        // Where z = z0 - gamma s passes the centre's height R.
        let (mut cyl, mut sph) = ((a, b), (a, b));
        if gamma.abs() > 1e-300 {
            // Not clamped into [a, b]: a stretch the split leaves empty stays empty
            // (a clamped one would read the cylinder at a point below the centre).
            let split = (z0 - corner) / gamma;
            if gamma > 0.0 {
                cyl.1 = cyl.1.min(split);
                sph.0 = sph.0.max(split);
            } else {
                cyl.0 = cyl.0.max(split);
                sph.1 = sph.1.min(split);
            }
        } else if z0 >= corner {
            sph = (1.0, 0.0);
        } else {
            cyl = (1.0, 0.0);
        }
        let mut best = f64::INFINITY;
        if cyl.0 <= cyl.1 {
            best = best.min(least(self.quad_a, quad_b, q_t - z0 * z0, cyl.0, cyl.1));
        }
        if sph.0 <= sph.1 {
            let (qb, qc) = (
                2.0 * (-self.qd - t * self.ed) + 2.0 * corner * gamma,
                q_t - 2.0 * corner * z0 + corner * corner,
            );
            best = best.min(least(self.dd, qb, qc, sph.0, sph.1));
        }
        best - self.tool.radius
    }

    /// [`Self::gap`] for a flat or bull-nose end on the move's stretch `(a, b)`: f at the
    /// minimiser of the distance from the axis when that lies on the cylinder, else a
    /// golden-section search over the move.
    #[inline]
    fn corner_gap(&self, t: f64, (a, b): (f64, f64), z0: f64, quad_b: f64) -> f64 {
        let quad_a = self.quad_a;
        let rho2 = |s: f64| quad_a * s * s + quad_b * s;
        let s_min = if quad_a > 1e-300 {
            (-quad_b / (2.0 * quad_a)).clamp(a, b)
        } else if rho2(a) <= rho2(b) {
            a
        } else {
            b
        };
        if z0 - self.gamma * s_min >= self.corner {
            self.f(t, s_min)
        } else {
            golden(a, b, GOLDEN_MOVE, &|s| self.f(t, s)).1
        }
    }

    /// The t-range (m) within `[lo, hi]` where some s keeps the slab: 0 <= alpha + beta t -
    /// gamma s <= h for an s in [0, 1], i.e. alpha + beta t in [min(0, gamma), h + max(0,
    /// gamma)]; `None` when empty.
    #[inline]
    fn t_range(&self, lo: f64, hi: f64) -> Option<(f64, f64)> {
        let (alpha, beta, gamma) = (self.alpha, self.beta, self.gamma);
        let (zlo, zhi) = (gamma.min(0.0), self.h + gamma.max(0.0));
        let (mut t0, mut t1) = (lo, hi);
        if beta.abs() > 1e-300 {
            let (p, q) = ((zlo - alpha) / beta, (zhi - alpha) / beta);
            t0 = t0.max(p.min(q));
            t1 = t1.min(p.max(q));
        } else if alpha < zlo || alpha > zhi {
            return None;
        }
        if t0 >= t1 {
            return None;
        }
        Some((t0, t1))
    }

    /// The zero of [`Self::gap`] between an inside point (gap <= 0) and an outside one:
    /// regula falsi with the Illinois modification (the retained end's value halved),
    /// bracket kept.
    #[inline]
    fn edge(&self, inside: f64, outside: f64) -> f64 {
        let g = |t: f64| self.gap(t);
        let (mut a, mut b) = (inside, outside);
        let (mut fa, mut fb) = (g(a), g(b));
        if !fb.is_finite() {
            // Just outside the slab: pull the outer end in until g is finite.
            for _ in 0..BISECT {
                let m = 0.5 * (a + b);
                let fm = g(m);
                if fm.is_finite() && fm > 0.0 {
                    b = m;
                    fb = fm;
                    break;
                }
                if fm <= 0.0 {
                    a = m;
                    fa = fm;
                } else {
                    b = m;
                }
            }
            if !fb.is_finite() {
                return 0.5 * (a + b);
            }
        }
        let mut side = 0i8;
        for _ in 0..BISECT {
            if (b - a).abs() < 1e-13 {
                break;
            }
            let m = (a * fb - b * fa) / (fb - fa);
            let m = if m.is_finite() && (m - a) * (m - b) < 0.0 {
                m
            } else {
                0.5 * (a + b)
            };
            let fm = g(m);
            if fm <= 0.0 {
                a = m;
                fa = fm;
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                b = m;
                fb = fm;
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
        }
        0.5 * (a + b)
    }
}

/// The least of A s^2 + B s + C on [a, b] (A >= 0), as sqrt(max(., 0)).
#[inline]
fn least(qa: f64, qb: f64, qc: f64, a: f64, b: f64) -> f64 {
    let at = |s: f64| ComplexField::sqrt((qa * s * s + qb * s + qc).max(0.0));
    if qa > 1e-300 {
        at((-qb / (2.0 * qa)).clamp(a, b))
    } else {
        at(a).min(at(b))
    }
}
