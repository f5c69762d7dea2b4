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
//! golden-section search to 1e-12 of the move.

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector2, Vector3};

use crate::error::{BuildError, TickError, check_finite};

/// Most cells of one z-map: 2^24 (16.8 million, 134 MB of heights; a 1 m x 1 m stock at
/// 0.25 mm). [`BuildError::Budget`] past it.
pub const MAX_CELLS: usize = 1 << 24;

/// A vertical cutter, its tip on the tool path (the tool axis along +z of the workpiece).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cutter {
    /// Flat end mill of radius \[m\].
    Flat {
        /// Radius \[m\].
        radius: f64,
    },
    /// Ball end mill of radius \[m\] (the tip is the lowest point of the ball).
    Ball {
        /// Radius \[m\].
        radius: f64,
    },
}

impl Cutter {
    /// The radius \[m\].
    pub fn radius(&self) -> f64 {
        match *self {
            Self::Flat { radius } | Self::Ball { radius } => radius,
        }
    }
}

/// What one cut removed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[must_use]
pub struct Removal {
    /// Cells whose height went down.
    pub cells: usize,
    /// Volume removed \[m^3\] (height drops times the cell area).
    pub volume: f64,
    /// The largest height drop of a cell \[m\].
    pub deepest: f64,
}

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
        check_finite("cut start", from.as_slice())?;
        check_finite("cut end", to.as_slice())?;
        let r = cutter.radius();
        if !(r.is_finite() && r > 0.0) {
            return Err(TickError::InvalidArgument {
                what: "cutter radius (finite, > 0 m)",
                value: r,
            });
        }
        // The cells whose centres can lie within r of the move.
        let lo = from.xy().inf(&to.xy()) - Vector2::repeat(r) - self.origin;
        let hi = from.xy().sup(&to.xy()) + Vector2::repeat(r) - self.origin;
        let index = |v: f64, n: usize| -> usize {
            let k = ComplexField::floor(v / self.cell - 0.5);
            if k <= 0.0 {
                0
            } else if k >= n as f64 {
                n
            } else {
                k as usize
            }
        };
        let (i0, i1) = (index(lo.x, self.nx), index(hi.x, self.nx).saturating_add(2));
        let (j0, j1) = (index(lo.y, self.ny), index(hi.y, self.ny).saturating_add(2));
        let mut removal = Removal::default();
        let area = self.cell * self.cell;
        for j in j0..j1.min(self.ny) {
            for i in i0..i1.min(self.nx) {
                let c = self.center(i, j);
                let Some(z) = lowest(cutter, from, to, &c) else {
                    continue;
                };
                if let Some(h) = self.heights.get_mut(j * self.nx + i)
                    && z < *h
                {
                    removal.cells += 1;
                    removal.volume += (*h - z) * area;
                    removal.deepest = removal.deepest.max(*h - z);
                    *h = z;
                }
            }
        }
        Ok(removal)
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
    // |a + t b|^2 <= r^2 for t in [t0, t1] (within [0, 1]).
    let (t0, t1) = if bb <= 1.0e-30 {
        if aa > r * r {
            return None;
        }
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
            let surface = |t: f64| {
                let d2 = (a + b * t).norm_squared();
                z(t) + radius - ComplexField::sqrt((radius * radius - d2).max(0.0))
            };
            // Convex on [t0, t1]: golden section, 60 steps take the bracket below 1e-12 of
            // the move.
            let inner = crate::golden::minimise(t0, t1, 60, surface, |f| *f);
            Some(surface(t0).min(surface(t1)).min(inner))
        }
    }
}
