//! The stock as a 2.5-D height field (a z-map): one height per square cell of the XY plane of
//! the workpiece frame, lowered by a vertical cutter swept along straight moves. What the
//! material-removal simulation of Hähn and Weigold (2020, Fig. 10-13) stands for: the part a
//! program leaves, and later the engagement the force model needs.
//!
//! A cell is cut when the cutter passes over its centre: its height becomes the lowest point
//! of the cutter surface above the centre during the move. For a flat end mill that is exact
//! (the tip height at the ends of the interval of the move during which the centre is under
//! the tool; the tip height is linear along the move); for a ball end mill the height
//! `z(t) + R - sqrt(R^2 - d(t)^2)` is convex in the move's parameter and is minimised by a
//! safeguarded Newton search on its derivative to 1e-12 of the move.
//!
//! A height is the mean over its cell: a cell whose centre lies within half a cell of the
//! cutter's rim (closest approach `d` of the move, `|d - R| < cell / 2`) is cut over the part
//! of the cell the cutter covers, `f = 1/2 + (R - d) / cell` (exact for a rim parallel to a
//! cell side), to `z + (top - z)(1 - f)` with `z` the cutter's surface under the rim (its
//! rim height past it) and `top` the stock's top. So the part, like the engagement, changes
//! continuously with the tool's position: a wall does not jump by a cell's full depth when
//! the tool moves a nanometre past a cell centre (the compensated tool, a few nanometres
//! off the program, cut whole cells the nominal tool did not).
//!
//! The engagement ([`super::engagement`]) reads the stock between cell centres as the
//! bilinear interpolation of the clipped depths `max(0, h - z)` of the four centres around a
//! point ([`ZMap::depth_at`]; outside the grid a centre counts as no material), a surface
//! continuous in the point and in `z`: what makes the force continuous in the tool's position.

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector2, Vector3};

use crate::error::{BuildError, TickError, check_finite};

mod cutter;
mod follower;
mod pass;
mod rows;
pub use cutter::{Cutter, Removal};
pub use follower::{FOLLOW_TOLERANCE, Follower, MAX_HELD, Step};
use pass::Pass;
use rows::Rows;

/// Most cells of one z-map: 2^24 (16.8 million, 134 MB of heights; a 1 m x 1 m stock at
/// 0.25 mm). [`BuildError::Budget`] past it.
pub const MAX_CELLS: usize = 1 << 24;

/// A rectangular stock of square cells, heights \[m\] in the workpiece frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ZMap {
    /// Lower corner (x, y) of cell (0, 0) \[m\].
    origin: Vector2<f64>,
    /// Cell edge \[m\].
    cell: f64,
    nx: usize,
    ny: usize,
    /// Row-major heights: cell (i, j) at `j * nx + i` (i along x).
    heights: Vec<f64>,
    /// The stock's top \[m\]: the height of the part of a cell the cutter's rim leaves.
    top: f64,
}

impl ZMap {
    /// The cells (along x, along y) of a stock over `[min, max]` (x, y) \[m\] with its top at
    /// `top` \[m\] and cells of `cell` \[m\], checked as [`Self::new`] checks them, without
    /// allocating: what a job validates before it runs.
    pub fn shape_for(
        min: Vector2<f64>,
        max: Vector2<f64>,
        top: f64,
        cell: f64,
    ) -> Result<(usize, usize), BuildError> {
        for (what, v) in [
            ("stock min x", min.x),
            ("stock min y", min.y),
            ("stock max x", max.x),
            ("stock max y", max.y),
            ("stock top", top),
        ] {
            if !v.is_finite() {
                return Err(BuildError::InvalidParameter {
                    what,
                    value: v,
                    expected: "finite (m)",
                });
            }
        }
        if !(cell.is_finite() && cell > 0.0) {
            return Err(BuildError::InvalidParameter {
                what: "cell size",
                value: cell,
                expected: "finite and > 0 (m)",
            });
        }
        let count = |lo: f64, hi: f64, what: &'static str| {
            if hi <= lo {
                return Err(BuildError::InvalidParameter {
                    what,
                    value: hi - lo,
                    expected: "> 0 (max above min, m)",
                });
            }
            let n = ComplexField::ceil((hi - lo) / cell - 1.0e-9);
            if n > MAX_CELLS as f64 {
                return Err(BuildError::Budget {
                    what: "z-map cells",
                    budget: "MAX_CELLS",
                    limit: MAX_CELLS,
                    requested: n.min(usize::MAX as f64) as usize,
                });
            }
            Ok((n as usize).max(1))
        };
        let nx = count(min.x, max.x, "stock x extent")?;
        let ny = count(min.y, max.y, "stock y extent")?;
        let cells = nx.saturating_mul(ny);
        if cells > MAX_CELLS {
            return Err(BuildError::Budget {
                what: "z-map cells",
                budget: "MAX_CELLS",
                limit: MAX_CELLS,
                requested: cells,
            });
        }
        Ok((nx, ny))
    }

    /// A flat stock over `[min, max]` (x, y) \[m\] with its top at `top` \[m\], cells of
    /// `cell` \[m\] (the last row and column may reach past `max`).
    ///
    /// [`BuildError::InvalidParameter`] for non-finite bounds, `max <= min` or a cell that is
    /// not finite and > 0; [`BuildError::Budget`] past [`MAX_CELLS`] or when the heights
    /// cannot be allocated.
    pub fn new(
        min: Vector2<f64>,
        max: Vector2<f64>,
        top: f64,
        cell: f64,
    ) -> Result<Self, BuildError> {
        let (nx, ny) = Self::shape_for(min, max, top, cell)?;
        let cells = nx * ny;
        let mut heights = Vec::new();
        heights
            .try_reserve_exact(cells)
            .map_err(|_| BuildError::Budget {
                what: "z-map cells (the allocation was refused)",
                budget: "MAX_CELLS",
                limit: MAX_CELLS,
                requested: cells,
            })?;
        heights.resize(cells, top);
        Ok(Self {
            origin: min,
            cell,
            nx,
            ny,
            heights,
            top,
        })
    }

    /// Cells along x and y.
    pub fn shape(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Cell edge \[m\].
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// Centre (x, y) of cell (i, j) \[m\].
    pub fn center(&self, i: usize, j: usize) -> Vector2<f64> {
        self.origin + Vector2::new(i as f64 + 0.5, j as f64 + 0.5) * self.cell
    }

    /// Height of cell (i, j) \[m\]; `None` outside the grid.
    pub fn height(&self, i: usize, j: usize) -> Option<f64> {
        if i >= self.nx {
            return None;
        }
        self.heights
            .get(j.checked_mul(self.nx)?.checked_add(i)?)
            .copied()
    }

    /// Height of the cell holding the point (x, y) \[m\]; `None` outside the grid (or for a
    /// non-finite point).
    pub fn height_at(&self, p: &Vector2<f64>) -> Option<f64> {
        let u = (p - self.origin) / self.cell;
        if !(u.x >= 0.0 && u.y >= 0.0 && u.x < self.nx as f64 && u.y < self.ny as f64) {
            return None;
        }
        // In range and non-negative: the casts truncate to the cell index.
        self.height(u.x as usize, u.y as usize)
    }

    /// Material above the height `z` at the point (x, y) \[m\]: the bilinear interpolation
    /// of the clipped depths `max(0, h - z)` of the four cell centres around it, a centre
    /// outside the grid counting 0 (so the depth falls to 0 over the half cell past the
    /// stock's edge). Continuous in the point and in `z`: it changes by at most `|dz|` for a
    /// change `dz` of `z`, and by at most `sqrt(2) D / cell` per metre of the point, `D` the
    /// largest clipped depth of the four centres. 0 for a non-finite point.
    #[inline]
    pub fn depth_at(&self, p: &Vector2<f64>, z: f64) -> f64 {
        let u = (p - self.origin) / self.cell - Vector2::repeat(0.5);
        self.depth_at_index(u.x, u.y, z)
    }

    /// [`Self::depth_at`] at the point of fractional cell coordinates (u, v) (cell (i, j)'s
    /// centre at (i, j)).
    #[inline]
    pub(crate) fn depth_at_index(&self, u: f64, v: f64, z: f64) -> f64 {
        // Far outside (or NaN): no material. The bounds keep the casts below exact.
        if !(u > -1.0 && v > -1.0 && u < self.nx as f64 && v < self.ny as f64) {
            return 0.0;
        }
        // u + 1 > 0: truncation is the floor (no libm call on the hot path).
        let (iu, iv) = ((u + 1.0) as usize, (v + 1.0) as usize);
        let (a, b) = (u + 1.0 - iu as f64, v + 1.0 - iv as f64);
        // Cell (iu - 1, iv - 1) is the lower corner; index 0 is the virtual cell before the
        // grid's first.
        let nx = self.nx;
        let clip = |h: f64| (h - z).max(0.0);
        let row = |j: usize| -> (f64, f64) {
            if j == 0 || j > self.ny {
                return (0.0, 0.0);
            }
            let base = (j - 1) * nx;
            if iu >= 1 && iu < nx {
                match self.heights.get(base + iu - 1..base + iu + 1) {
                    Some(&[h0, h1]) => (clip(h0), clip(h1)),
                    _ => (0.0, 0.0),
                }
            } else if iu == 0 {
                (0.0, self.heights.get(base).map_or(0.0, |&h| clip(h)))
            } else {
                (
                    self.heights.get(base + nx - 1).map_or(0.0, |&h| clip(h)),
                    0.0,
                )
            }
        };
        let (d00, d10) = row(iv);
        let (d01, d11) = row(iv + 1);
        let low = d00 + (d10 - d00) * a;
        let high = d01 + (d11 - d01) * a;
        low + (high - low) * b
    }

    /// Lower corner (x, y) of cell (0, 0) \[m\].
    pub fn origin(&self) -> Vector2<f64> {
        self.origin
    }

    /// Every height, row-major (cell (i, j) at `j * nx + i`) \[m\].
    pub fn heights(&self) -> &[f64] {
        &self.heights
    }

    /// Sweeps `cutter` with its tip from `from` to `to` \[m\] (a straight move, workpiece
    /// frame) and lowers every cell it passes over. [`TickError::NonFinite`] for non-finite
    /// points, [`TickError::InvalidArgument`] for a radius that is not finite and > 0.
    pub fn cut(
        &mut self,
        cutter: &Cutter,
        from: &Vector3<f64>,
        to: &Vector3<f64>,
    ) -> Result<Removal, TickError> {
        self.sweep(cutter, from, to, false)
    }

    /// Whether a followed step may visit the crescent only (flat end, shorter than a cell).
    fn crescent(&self, cutter: &Cutter, from: &Vector3<f64>, to: &Vector3<f64>) -> bool {
        matches!(cutter, Cutter::Flat { .. }) && (to.xy() - from.xy()).norm() < self.cell
    }

    /// Sweeps `cutter` from `from` to `to` \[m\] (see [`Self::cut`]); `after` for a followed
    /// step, which visits the crescent only where it may ([`Self::crescent`]).
    fn sweep(
        &mut self,
        cutter: &Cutter,
        from: &Vector3<f64>,
        to: &Vector3<f64>,
        after: bool,
    ) -> Result<Removal, TickError> {
        check_finite("cut start", from.as_slice())?;

        check_finite("cut end", to.as_slice())?;
        let r = cutter.radius();
        if !(r.is_finite() && r > 0.0) {
            return Err(TickError::InvalidArgument {
                what: "cutter radius (finite, > 0 m)",
                value: r,
            });
        }
        // No cell rises above the top: a move above it (a rapid, air) cuts nothing.
        if from.z.min(to.z) >= self.top {
            return Ok(Removal::default());
        }
        let cell = self.cell;
        // A step shorter than a cell: every cell it reaches lies within r + cell of an end.
        let short = (to.xy() - from.xy()).norm() < cell;
        let crescent = after && self.crescent(cutter, from, to);
        let (i0, i1, j0, j1) = self.window(from, to, r);
        let (nx, origin) = (self.nx, self.origin);
        let pass = Pass {
            cutter,
            from,
            to,
            // No point of the cutter's surface lies below the lower end of the move.
            floor: from.z.min(to.z),
            p0: from.xy(),
            b: to.xy() - from.xy(),
            inv_bb: {
                let bb = (to.xy() - from.xy()).norm_squared();
                if bb > 1.0e-30 { 1.0 / bb } else { 0.0 }
            },
            r,
            top: self.top,
            area: cell * cell,
        };
        let mut removal = Removal::default();
        let rows = Rows::new(&pass, cell, origin.x, i0, i1);
        for j in j0..j1 {
            let cy = origin.y + (j as f64 + 0.5) * cell;
            let Some(row) = self.heights.get_mut(j * nx..(j + 1) * nx) else {
                continue;
            };
            if crescent {
                rows.crescent(row, cy, &mut removal);
            } else if short {
                rows.short(row, cy, &mut removal);
            } else {
                rows.whole(row, cy, &mut removal);
            }
        }
        Ok(removal)
    }

    /// The cells whose centres can lie within `r` \[m\] of the move from `from` to `to`:
    /// columns `[i0, i1)` and rows `[j0, j1)`, clamped to the grid.
    fn window(
        &self,
        from: &Vector3<f64>,
        to: &Vector3<f64>,
        r: f64,
    ) -> (usize, usize, usize, usize) {
        let cell = self.cell;
        let lo = from.xy().inf(&to.xy()) - Vector2::repeat(r + 0.5 * cell) - self.origin;
        let hi = from.xy().sup(&to.xy()) + Vector2::repeat(r + 0.5 * cell) - self.origin;
        let index = |v: f64, n: usize| -> usize {
            let k = ComplexField::floor(v / cell - 0.5);
            if k <= 0.0 {
                0
            } else if k >= n as f64 {
                n
            } else {
                k as usize
            }
        };
        let nx = self.nx;
        let i1 = index(hi.x, nx).saturating_add(2).min(nx);
        let i0 = index(lo.x, nx).min(i1);
        let (j0, j1) = (
            index(lo.y, self.ny),
            index(hi.y, self.ny).saturating_add(2).min(self.ny),
        );
        (i0, i1, j0, j1)
    }
}
