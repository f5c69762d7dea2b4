//! One sweep of a cutter over a z-map, cell by cell: the lowest point of the cutter above
//! each cell's centre during a straight move, with the rim's band (see the parent's docs).

use nalgebra::{ComplexField, Vector2, Vector3};

use super::cutter::{Cutter, Removal};

/// One sweep of a cutter, cell by cell.
pub(super) struct Pass<'a> {
    pub(super) cutter: &'a Cutter,
    pub(super) from: &'a Vector3<f64>,
    pub(super) to: &'a Vector3<f64>,
    pub(super) floor: f64,
    pub(super) p0: Vector2<f64>,
    pub(super) b: Vector2<f64>,
    /// `1 / |b|^2` (0 for a step without horizontal motion).
    pub(super) inv_bb: f64,
    pub(super) r: f64,
    pub(super) top: f64,
    pub(super) area: f64,
}

impl Pass<'_> {
    /// Lowers the cells `i0..i1` of one row (centre height `cy`), each to the lowest point
    /// of the cutter above its centre (see [`ZMap::cut`] for the rim's band). A cell at or below the lower end of the move keeps
    /// its height (most cells under a tool cutting a floor), and for a ball one at or below
    /// `floor + R - sqrt(R^2 - d^2)` at `d` from the move (the cells the last samples left
    /// on the ball's surface) is passed over without a search.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn row(
        &self,
        row: &mut [f64],
        i0: usize,
        i1: usize,
        cy: f64,
        ox: f64,
        cell: f64,
        removal: &mut Removal,
    ) {
        let Some(cells) = row.get_mut(i0..i1.max(i0)) else {
            return;
        };

        let inv_bb = self.inv_bb;
        let ball = matches!(self.cutter, Cutter::Ball { .. });
        let (r, floor) = (self.r, self.floor);
        let r2 = r * r;
        // The rim's band: cells within half a cell of the rim are cut in proportion to the
        // part of the cell the cutter covers.
        let inner = (r - 0.5 * cell).max(0.0);
        let (inner2, outer2) = (inner * inner, (r + 0.5 * cell) * (r + 0.5 * cell));
        for (k, h) in cells.iter_mut().enumerate() {
            if *h <= floor {
                continue;
            }
            let c = Vector2::new(ox + ((i0 + k) as f64 + 0.5) * cell, cy);
            let a = self.p0 - c;
            let t = (-a.dot(&self.b) * inv_bb).clamp(0.0, 1.0);
            let d2 = (a + self.b * t).norm_squared();
            if d2 > outer2 {
                continue;
            }
            let z = if d2 > inner2 {
                // The surface under the rim (or the rim's height at the closest approach,
                // past it), raised towards the stock's top over the part of the cell the
                // cutter does not cover: continuous in the tool's position.
                let d = ComplexField::sqrt(d2);
                let rim = |t: f64| {
                    let z = self.from.z + (self.to.z - self.from.z) * t;
                    if ball { z + r } else { z }
                };
                let under = if d2 <= r2 {
                    lowest(self.cutter, self.from, self.to, &c)
                } else {
                    None
                };
                let zs = under.unwrap_or_else(|| rim(t));
                let covered = ((r - d) / cell + 0.5).clamp(0.0, 1.0);
                Some(zs + (self.top - zs).max(0.0) * (1.0 - covered))
            } else if ball {
                let rise = r + floor - *h;
                if rise >= 0.0 && d2 >= r2 - rise * rise {
                    continue;
                }
                lowest(self.cutter, self.from, self.to, &c)
            } else if a.norm_squared() <= r2 && (a + self.b).norm_squared() <= r2 {
                // Under the flat end at both ends of the move (so all along it: the distance
                // is convex in the move's parameter): its lowest point is the lower end.
                Some(floor)
            } else {
                lowest(self.cutter, self.from, self.to, &c)
            };
            let Some(z) = z else {
                continue;
            };
            if z < *h {
                removal.cells += 1;
                removal.volume += (*h - z) * self.area;
                removal.deepest = removal.deepest.max(*h - z);
                *h = z;
            }
        }
    }
}

impl Pass<'_> {
    /// Lowers the cells `i0..i1` of one row to the move's lower end (cells a flat end covers
    /// all along the move).
    pub(super) fn floor(&self, row: &mut [f64], i0: usize, i1: usize, removal: &mut Removal) {
        let Some(cells) = row.get_mut(i0..i1.max(i0)) else {
            return;
        };
        let floor = self.floor;
        for h in cells {
            if *h > floor {
                removal.cells += 1;
                removal.volume += (*h - floor) * self.area;
                removal.deepest = removal.deepest.max(*h - floor);
                *h = floor;
            }
        }
    }
}

/// The lowest point of the cutter surface above `c` during the move, if the move passes
/// within the radius of `c`.
fn lowest(
    cutter: &Cutter,
    from: &Vector3<f64>,
    to: &Vector3<f64>,
    c: &Vector2<f64>,
) -> Option<f64> {
    let r = cutter.radius();
    let a = from.xy() - c;
    let b = to.xy() - from.xy();
    let (bb, ab, aa) = (b.dot(&b), a.dot(&b), a.dot(&a));
    // |a + t b|^2 <= r^2 for t in [t0, t1] (within [0, 1]); under the cutter at both ends,
    // all along (the distance is convex in t).
    let (t0, t1) = if bb <= 1.0e-30 {
        if aa > r * r {
            return None;
        }
        (0.0, 1.0)
    } else if aa <= r * r && (a + b).norm_squared() <= r * r {
        (0.0, 1.0)
    } else {
        let disc = ab * ab - bb * (aa - r * r);
        if disc < 0.0 {
            return None;
        }
        let s = ComplexField::sqrt(disc);
        ((-ab - s) / bb, (-ab + s) / bb)
    };
    let (t0, t1) = (t0.max(0.0), t1.min(1.0));
    if t0 > t1 {
        return None;
    }
    let z = |t: f64| from.z + (to.z - from.z) * t;
    match cutter {
        Cutter::Flat { .. } => Some(z(t0).min(z(t1))),
        Cutter::Ball { radius } => {
            let r2 = radius * radius;
            let dz = to.z - from.z;
            let surface = |t: f64| {
                let d2 = (a + b * t).norm_squared();
                z(t) + radius - ComplexField::sqrt((r2 - d2).max(0.0))
            };
            // The surface is convex in t: its slope dz + (a + b t).b / sqrt(R^2 - d^2) rises
            // from t0 to t1. Its root by Newton's method kept inside a shrinking bracket.
            let slope = |t: f64| {
                let w = a + b * t;
                let root = ComplexField::sqrt((r2 - w.norm_squared()).max(0.0));
                let wb = w.dot(&b);
                if root > 0.0 {
                    (
                        dz + wb / root,
                        (bb * root * root + wb * wb) / (root * root * root),
                    )
                } else if wb < 0.0 {
                    (f64::NEG_INFINITY, f64::INFINITY)
                } else {
                    (f64::INFINITY, f64::INFINITY)
                }
            };
            // Most cells: the slope at t0 is >= 0 and the lowest point is there (one root), or
            // the slope at t1 is <= 0 and it is at t1 (two).
            let (lo_s, _) = slope(t0);
            if lo_s >= 0.0 || lo_s.is_nan() || t1 - t0 <= 1.0e-12 {
                return Some(surface(t0));
            }
            let (hi_s, _) = slope(t1);
            if hi_s <= 0.0 || hi_s.is_nan() {
                return Some(surface(t1).min(surface(t0)));
            }
            let (mut lo, mut hi) = (t0, t1);
            let mut t = 0.5 * (t0 + t1);
            for _ in 0..100 {
                let (g, h) = slope(t);
                if g < 0.0 {
                    lo = t;
                } else {
                    hi = t;
                }
                if hi - lo <= 1.0e-12 || g == 0.0 {
                    break;
                }
                let newton = t - g / h;
                if newton > lo && newton < hi && h.is_finite() {
                    let step = newton - t;
                    t = newton;
                    if step.abs() <= 1.0e-13 {
                        break;
                    }
                } else {
                    t = 0.5 * (lo + hi);
                }
            }
            Some(surface(t0).min(surface(t1)).min(surface(t)))
        }
    }
}
