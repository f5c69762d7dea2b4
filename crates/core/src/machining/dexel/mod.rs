//! The stock as tri-dexels: three grids of rays along x, y and z of the workpiece frame, each
//! holding the intervals of material it passes through, cut by a tool at any orientation. What
//! a five-axis program needs where the z-map ([`super::stock`]) cannot go: a tilted tool
//! cuts under itself, a swarf cut leaves an inclined wall, an undercut keeps material above a
//! pocket.
//!
//! The tool is the cutter's solid of revolution: radius `R(z)` at height `z` above the tip
//! along its axis (the corner's arc, then the cylinder up to the cutting length; flat, ball
//! and bull-nose ends as [`super::profile::Profile`]), a convex solid. A straight move with a
//! fixed axis sweeps it into a convex solid, and every ray meets that in one interval, found
//! exactly: along the ray (parameter `t`) and the move (parameter `s`) the function
//! `rho(t, s) - R(z(t, s))` (distance from the axis less the radius at that height) is convex
//! on the slab `0 <= z <= length` (a norm of an affine map less a concave function of an
//! affine one), so its minimum over `s` is convex in `t`; golden-section searches find the
//! deepest point and a regula falsi the interval's ends, to 1e-13 m. A move whose axis
//! turns is cut as straight pieces with the axis of each piece's middle, as many as keep the
//! tool's far end within a quarter cell of the turning one.
//!
//! Rays run through the centres of the grid's cells (`cell` apart); a point's material is
//! read from the z-ray nearest it. Memory: 24 bytes per ray and 16 per interval, budgets
//! [`MAX_RAYS`] and [`MAX_INTERVALS`]; a cut that would pass the latter is refused.

use alloc::vec::Vec;

use nalgebra::{ComplexField, Vector3};

use super::profile::Profile;

mod engage;
pub mod surface;
mod sweep;
use crate::error::{BuildError, TickError};
pub use engage::MAX_ENGAGEMENT_SAMPLES;

/// Most rays of one stock (the three grids together): 2^25 (33.5 million, 0.8 GB of ray
/// headers; a 0.5 m cube at 0.15 mm).
pub const MAX_RAYS: usize = 1 << 25;

/// Most material intervals one stock may hold: 2^26 (67 million, 1.1 GB).
pub const MAX_INTERVALS: usize = 1 << 26;

/// Most straight pieces one move is cut as (a turning axis' pieces, an arc's chords): 65,536;
/// past it [`TickError::Budget`] (a half turn of a 1 m reach at 0.1 mm rays would be 63,000).
pub const MAX_PIECES: usize = 1 << 16;

/// `n` pieces, or [`TickError::Budget`] past [`MAX_PIECES`].
fn pieces(n: f64, what: &'static str) -> Result<usize, TickError> {
    let n = ComplexField::ceil(n).max(1.0);
    if n.is_nan() || n > MAX_PIECES as f64 {
        return Err(TickError::Budget {
            what,
            budget: "MAX_PIECES",
            limit: MAX_PIECES as f64,
            requested: n,
        });
    }
    Ok(n as usize)
}

/// The tool as a solid of revolution: radius, corner radius and the length above the tip
/// that removes material \[m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DexelTool {
    radius: f64,
    corner: f64,
    length: f64,
}

impl DexelTool {
    /// The solid of `profile` up to `length` above the tip (the flutes and the shank that
    /// would rub: `length` at least the corner radius, at most 1 m).
    /// [`BuildError::InvalidParameter`] otherwise.
    pub fn new(profile: &Profile, length: f64) -> Result<Self, BuildError> {
        crate::error::param(
            "dexel tool length",
            length,
            length >= profile.corner() && length > 0.0 && length <= 1.0,
            "finite, at least the corner radius, at most 1 m",
        )?;
        Ok(Self {
            radius: profile.radius(),
            corner: profile.corner(),
            length,
        })
    }

    /// The radius \[m\] at height `z` in `[0, length]` above the tip (concave in `z`).
    pub fn radius_at(&self, z: f64) -> f64 {
        let r = self.corner;
        if z >= r {
            self.radius
        } else {
            let d = r - z;
            self.radius - r + ComplexField::sqrt((r * r - d * d).max(0.0))
        }
    }

    /// The length above the tip \[m\].
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Whether `p` lies in the tool with its tip at `tip` and axis `axis` (unit).
    pub fn contains(&self, tip: &Vector3<f64>, axis: &Vector3<f64>, p: &Vector3<f64>) -> bool {
        let w = p - tip;
        let z = w.dot(axis);
        (0.0..=self.length).contains(&z) && (w - axis * z).norm() <= self.radius_at(z)
    }
}

/// What one cut removed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[must_use]
pub struct DexelRemoval {
    /// Rays whose material changed (all three grids).
    pub rays: usize,
    /// Volume removed \[m^3\], from the z-rays (removed length times the cell's area).
    pub volume: f64,
}

/// One ray's material: sorted, disjoint intervals along its direction \[m\].
pub type Intervals = [(f64, f64)];

/// A block of stock as tri-dexels (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Dexels {
    min: Vector3<f64>,
    cell: f64,
    n: [usize; 3],
    /// Per direction (x, y, z), rays by `(i, j)` of the two other axes in cyclic order,
    /// `i * n_v + j`, each its sorted, disjoint material intervals along the direction.
    rays: [Vec<Vec<(f64, f64)>>; 3],
    intervals: usize,
}

/// The two axes across direction `d`, cyclic: x -> (y, z), y -> (z, x), z -> (x, y).
fn across(d: usize) -> (usize, usize) {
    ((d + 1) % 3, (d + 2) % 3)
}

pub(crate) fn at(v: &Vector3<f64>, i: usize) -> f64 {
    v.get(i).copied().unwrap_or(0.0)
}

fn count(n: &[usize; 3], i: usize) -> usize {
    n.get(i).copied().unwrap_or(0)
}

impl Dexels {
    /// A full block over `[min, max]` \[m\] with rays `cell` \[m\] apart (the block's far
    /// faces rounded up to whole cells). [`BuildError::InvalidParameter`] for non-finite
    /// bounds, `max <= min` or a cell not finite and > 0; [`BuildError::Budget`] past
    /// [`MAX_RAYS`] or [`MAX_INTERVALS`], or when the memory is refused.
    pub fn block(min: Vector3<f64>, max: Vector3<f64>, cell: f64) -> Result<Self, BuildError> {
        crate::error::param("dexel cell", cell, cell > 0.0, "finite and > 0 m")?;
        let mut n = [0usize; 3];
        for (d, slot) in n.iter_mut().enumerate() {
            let (lo, hi) = (at(&min, d), at(&max, d));
            crate::error::param("dexel block bound", lo, lo.is_finite(), "finite")?;
            crate::error::param(
                "dexel block bound",
                hi,
                hi > lo,
                "finite, above the minimum",
            )?;
            let cells = ComplexField::ceil((hi - lo) / cell - 1e-9);
            if cells.is_nan() || cells > MAX_RAYS as f64 {
                return Err(BuildError::Budget {
                    what: "dexel cells along one axis",
                    budget: "MAX_RAYS",
                    limit: MAX_RAYS,
                    requested: usize::MAX,
                });
            }
            *slot = (cells as usize).max(1);
        }
        let [nx, ny, nz] = n;
        let rays = [
            ny.saturating_mul(nz),
            nz.saturating_mul(nx),
            nx.saturating_mul(ny),
        ];
        let total = rays.iter().fold(0usize, |a, &b| a.saturating_add(b));
        if total > MAX_RAYS || total > MAX_INTERVALS {
            return Err(BuildError::Budget {
                what: "dexel rays (the three grids)",
                budget: "MAX_RAYS",
                limit: MAX_RAYS,
                requested: total,
            });
        }
        let mut grids: [Vec<Vec<(f64, f64)>>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        for (d, grid) in grids.iter_mut().enumerate() {
            let count = rays.get(d).copied().unwrap_or(0);
            grid.try_reserve_exact(count)
                .map_err(|_| BuildError::Budget {
                    what: "dexel rays (the allocation was refused)",
                    budget: "MAX_RAYS",
                    limit: MAX_RAYS,
                    requested: total,
                })?;
            let lo = at(&min, d);
            let hi = lo + cell * self::count(&n, d) as f64;
            for _ in 0..count {
                let mut ray = Vec::new();
                ray.try_reserve_exact(1).map_err(|_| BuildError::Budget {
                    what: "dexel intervals (the allocation was refused)",
                    budget: "MAX_INTERVALS",
                    limit: MAX_INTERVALS,
                    requested: total,
                })?;
                ray.push((lo, hi));
                grid.push(ray);
            }
        }
        Ok(Self {
            min,
            cell,
            n,
            rays: grids,
            intervals: total,
        })
    }

    /// The spacing of the rays \[m\].
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// Cells along x, y and z.
    pub fn shape(&self) -> [usize; 3] {
        self.n
    }

    /// The intervals of material currently held (all grids).
    pub fn intervals(&self) -> usize {
        self.intervals
    }

    /// The ray along direction `d` (0 x, 1 y, 2 z) at cell `(i, j)` of the two axes across it
    /// (cyclic: x -> (y, z), y -> (z, x), z -> (x, y)): its point at the block's near face and
    /// its material intervals along `d` \[m\]; `None` outside the grid.
    pub fn ray(&self, d: usize, i: usize, j: usize) -> Option<(Vector3<f64>, &Intervals)> {
        let (u, v) = across(d);
        let (nu, nv) = (count(&self.n, u), count(&self.n, v));
        if i >= nu || j >= nv {
            return None;
        }
        let ray = self.rays.get(d)?.get(i * nv + j)?;
        let mut o = self.min;
        if let Some(x) = o.get_mut(u) {
            *x += (i as f64 + 0.5) * self.cell;
        }
        if let Some(x) = o.get_mut(v) {
            *x += (j as f64 + 0.5) * self.cell;
        }
        Some((o, ray.as_slice()))
    }

    /// Whether `p` is material, read from the z-ray nearest it (outside the block: no).
    pub fn is_material(&self, p: &Vector3<f64>) -> bool {
        self.is_material_along(p, 2)
    }

    /// Whether `p` is material, read from the ray along direction `d` (0 x, 1 y, 2 z) nearest
    /// it: exact along `d`, within half a cell across it (so read along the direction closest
    /// to the material boundary's normal; outside the block: no).
    pub fn is_material_along(&self, p: &Vector3<f64>, d: usize) -> bool {
        let (u, v) = across(d);
        let index = |k: usize| {
            let x = (at(p, k) - at(&self.min, k)) / self.cell;
            (x >= 0.0 && x < count(&self.n, k) as f64).then_some(x as usize)
        };
        let (Some(i), Some(j)) = (index(u), index(v)) else {
            return false;
        };
        let x = at(p, d);
        self.ray(d, i, j)
            .is_some_and(|(_, r)| r.iter().any(|&(a, b)| x >= a && x <= b))
    }

    /// The material's volume \[m^3\] from the z-rays.
    pub fn volume(&self) -> f64 {
        let area = self.cell * self.cell;
        self.rays.get(2).map_or(0.0, |g| {
            g.iter()
                .map(|r| r.iter().map(|(a, b)| b - a).sum::<f64>())
                .sum::<f64>()
                * area
        })
    }

    /// Cuts `tool` swept from `from` to `to` (tips \[m\]) with the axis turning from
    /// `from_axis` to `to_axis` (unit; along the great circle), workpiece frame.
    /// [`TickError::NonFinite`] for non-finite input, [`TickError::InvalidArgument`] for an
    /// axis not of unit length (within 1e-9) or axes opposite, [`TickError::Budget`] when the
    /// material would pass [`MAX_INTERVALS`] or the turn take more than [`MAX_PIECES`].
    pub fn cut(
        &mut self,
        tool: &DexelTool,
        from: &Vector3<f64>,
        from_axis: &Vector3<f64>,
        to: &Vector3<f64>,
        to_axis: &Vector3<f64>,
    ) -> Result<DexelRemoval, TickError> {
        for (what, v) in [
            ("cut start", from),
            ("cut start axis", from_axis),
            ("cut end", to),
            ("cut end axis", to_axis),
        ] {
            crate::error::check_finite(what, v.as_slice())?;
        }
        for a in [from_axis, to_axis] {
            if (a.norm() - 1.0).abs() > 1e-9 {
                return Err(TickError::InvalidArgument {
                    what: "cut axis (unit length within 1e-9)",
                    value: a.norm(),
                });
            }
        }
        let turn = super::program::angle_between(from_axis, to_axis);
        if turn > super::MAX_AXIS_TURN {
            return Err(TickError::InvalidArgument {
                what: "cut axis turn (at most MAX_AXIS_TURN, 179 degrees)",
                value: turn,
            });
        }
        // Pieces keeping the far end of the tool within a quarter cell of the turning axis.
        let reach = tool.length + tool.radius;
        let pieces = pieces(
            turn * reach / (0.25 * self.cell),
            "pieces of a turning axis (a quarter cell of the tool's far end each)",
        )?;
        let mut total = DexelRemoval::default();
        for k in 0..pieces {
            let (s0, s1) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
            let axis = super::program::slerp(from_axis, to_axis, 0.5 * (s0 + s1));
            let a = from + (to - from) * s0;
            let b = from + (to - from) * s1;
            let r = self.sweep(tool, &a, &b, &axis)?;
            total.rays += r.rays;
            total.volume += r.volume;
        }
        Ok(total)
    }

    /// Cuts every move of `program` in order (rapids too: a rapid through material is the
    /// program's fault, and the stock shows it), arcs as chords whose sagitta stays within an
    /// eighth of a cell, dwells cutting nothing. Errors of [`Self::cut`], and
    /// [`TickError::InvalidArgument`] for a program [`super::Program::validate`] refuses.
    pub fn cut_program(
        &mut self,
        tool: &DexelTool,
        program: &super::Program,
    ) -> Result<DexelRemoval, TickError> {
        program.validate().map_err(|_| TickError::InvalidArgument {
            what: "program (Program::validate refuses it)",
            value: f64::NAN,
        })?;
        let mut total = DexelRemoval::default();
        for m in &program.moves {
            let r = self.cut_move(tool, m)?;
            total.rays += r.rays;
            total.volume += r.volume;
        }
        Ok(total)
    }

    /// Cuts one move of a program ([`Self::cut_program`] cuts them all): arcs as chords whose
    /// sagitta stays within an eighth of a cell, a dwell cutting nothing. Errors of
    /// [`Self::cut`].
    pub fn cut_move(
        &mut self,
        tool: &DexelTool,
        m: &super::Move,
    ) -> Result<DexelRemoval, TickError> {
        let chords = match m.motion {
            super::Motion::Dwell { .. } => return Ok(DexelRemoval::default()),
            super::Motion::Arc { sweep, .. } => {
                let r = m.radius().max(m.end_radius());
                let half = ComplexField::acos((1.0 - 0.125 * self.cell / r).clamp(-1.0, 1.0));
                pieces(
                    ComplexField::abs(sweep) / (2.0 * half).max(1e-6),
                    "chords of an arc (an eighth of a cell of sagitta each)",
                )?
            }
            _ => 1,
        };
        let mut total = DexelRemoval::default();
        for k in 0..chords {
            let (s0, s1) = (k as f64 / chords as f64, (k + 1) as f64 / chords as f64);
            let r = self.cut(tool, &m.point(s0), &m.axis(s0), &m.point(s1), &m.axis(s1))?;
            total.rays += r.rays;
            total.volume += r.volume;
        }
        Ok(total)
    }
}
