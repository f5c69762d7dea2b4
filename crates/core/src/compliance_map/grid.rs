//! Grid axes: validation, cell lookup and the 1-D interpolation weights ("stencils") whose
//! tensor product gives the 2-D weights of Eq. 14 (bilinear) or of the cubic Hermite option.
//!
//! Everything here is allocation-free and panic-free: indices are reached through `.get()`.

use super::{Interpolation, OutOfGrid};
use crate::error::{BuildError, Placement, TickError};

/// Relative tolerance under which an axis counts as evenly spaced (O(1) cell lookup).
const UNIFORM_RTOL: f64 = 1e-12;

/// One grid axis: strictly increasing finite node coordinates \[m\].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Axis<'a> {
    pub nodes: &'a [f64],
    /// `1 / step` when the axis is evenly spaced, `0.0` otherwise (binary search).
    pub inv_step: f64,
}

/// A grid axis as errors name it: the 2-D map's `x` and `y`, or axis `k` (0 to 3) of an N-D
/// grid. The names are static strings because the errors carry `&'static str`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AxisId {
    /// The 2-D map's x axis.
    X,
    /// The 2-D map's y axis.
    Y,
    /// Axis `k` of an N-D grid, `k < MAX_GRID_DIMS` (the N-D grid needs `alloc`).
    #[cfg_attr(not(feature = "alloc"), allow(dead_code))]
    Grid(usize),
}

/// The N-D grid axes' names, then their node lists' names.
const GRID_NAMES: [&str; 4] = ["axis 0", "axis 1", "axis 2", "axis 3"];
const GRID_NODE_NAMES: [&str; 4] = [
    "axis 0 nodes",
    "axis 1 nodes",
    "axis 2 nodes",
    "axis 3 nodes",
];

impl AxisId {
    /// The axis' name in errors ("x", "axis 2").
    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::X => "x",
            Self::Y => "y",
            Self::Grid(k) => GRID_NAMES.get(k).copied().unwrap_or("grid axis"),
        }
    }

    /// The name of the axis' node list in errors ("x nodes", "axis 2 nodes").
    fn nodes_name(self) -> &'static str {
        match self {
            Self::X => "x nodes",
            Self::Y => "y nodes",
            Self::Grid(k) => GRID_NODE_NAMES.get(k).copied().unwrap_or("grid axis nodes"),
        }
    }
}

/// Checks an axis (at least 2 nodes, finite, strictly increasing) and returns `1/step` when
/// it is evenly spaced, else `0.0`.
pub(crate) fn check_axis(id: AxisId, nodes: &[f64]) -> Result<f64, BuildError> {
    let axis = id.name();
    if nodes.len() < 2 {
        return Err(BuildError::TooFew {
            what: id.nodes_name(),
            needed: 2,
            got: nodes.len(),
        });
    }
    for (index, v) in nodes.iter().enumerate() {
        if !v.is_finite() {
            return Err(BuildError::NonFinite { what: axis, index });
        }
    }
    for (index, w) in nodes.windows(2).enumerate() {
        if let [a, b] = w
            && b <= a
        {
            return Err(BuildError::NotIncreasing {
                what: axis,
                index: index + 1,
            });
        }
    }
    Ok(uniform_inv_step(nodes))
}

fn uniform_inv_step(nodes: &[f64]) -> f64 {
    let (Some(&first), Some(&last)) = (nodes.first(), nodes.last()) else {
        return 0.0;
    };
    let n = nodes.len();
    if n < 2 {
        return 0.0;
    }
    let step = (last - first) / (n - 1) as f64;
    let scale = first.abs().max(last.abs()).max(last - first);
    let even = nodes
        .iter()
        .enumerate()
        .all(|(k, v)| (v - (first + k as f64 * step)).abs() <= UNIFORM_RTOL * scale);
    if even && step > 0.0 { 1.0 / step } else { 0.0 }
}

impl<'a> Axis<'a> {
    #[inline(always)]
    fn node(&self, k: usize) -> f64 {
        self.nodes.get(k).copied().unwrap_or(0.0)
    }

    /// Index `i` of the cell `[x_i, x_{i+1}]` holding `v` (`v` already within the axis, or
    /// the boundary cell when outside). O(1) on evenly spaced axes, binary search otherwise.
    #[inline(always)]
    fn cell(&self, v: f64) -> usize {
        self.cell_nodes(v).0
    }

    /// [`Self::cell`] and the cell's two node coordinates, loaded once.
    #[inline(always)]
    fn cell_nodes(&self, v: f64) -> (usize, f64, f64) {
        let n = self.nodes.len();
        let last_cell = n.saturating_sub(2);
        if self.inv_step > 0.0 {
            let mut i = even_estimate(v, self.node(0), self.inv_step, last_cell);
            // One step of correction against rounding at the node coordinates. The test
            // that decides it is rarely true whatever the cell; the cell's own tests
            // (`i > 0`, `i < last_cell`) only run then: on scattered queries (a batch over
            // the workspace) they were data-dependent branches, mispredicted about every
            // other row (random points 26-31 ns against 18 ns per query).
            let (lo, hi) = (self.node(i), self.node(i + 1));
            if v < lo || v > hi {
                if i > 0 && v < lo {
                    i -= 1;
                } else if i < last_cell && v > hi {
                    i += 1;
                }
                return (i, self.node(i), self.node(i + 1));
            }
            (i, lo, hi)
        } else {
            // Number of nodes <= v, minus one, kept within the cells.
            let i = self
                .nodes
                .partition_point(|x| *x <= v)
                .saturating_sub(1)
                .min(last_cell);
            (i, self.node(i), self.node(i + 1))
        }
    }

    /// Locates `v`: the cell index, the coordinate to evaluate at (clamped if so asked) and
    /// where it fell. `axis` (0 = x, 1 = y) names it in errors.
    #[inline(always)]
    fn locate(
        &self,
        axis: usize,
        v: f64,
        policy: OutOfGrid,
    ) -> Result<(usize, f64, Placement), TickError> {
        let lo = self.node(0);
        let hi = self.node(self.nodes.len().saturating_sub(1));
        if v >= lo && v <= hi {
            return Ok((self.cell(v), v, Placement::Inside));
        }
        match policy {
            OutOfGrid::Error => Err(TickError::OutOfGrid {
                axis,
                value: v,
                min: lo,
                max: hi,
            }),
            OutOfGrid::Clamp => {
                let c = v.clamp(lo, hi);
                Ok((self.cell(c), c, Placement::Clamped))
            }
            OutOfGrid::Extrapolate => Ok((self.cell(v), v, Placement::Extrapolated)),
        }
    }

    /// Weights of the nodes for the derivative at node `k` of the cubic Hermite option:
    /// the three-point finite difference that is exact for quadratics on uneven spacing
    /// (central inside, one-sided at the ends; the plain secant when the axis has 2 nodes).
    fn slope_weights(&self, k: usize) -> ([usize; 3], [f64; 3]) {
        let n = self.nodes.len();
        let x = |i: usize| self.node(i);
        if n < 3 {
            let h = x(1) - x(0);
            return ([0, 1, 1], [-1.0 / h, 1.0 / h, 0.0]);
        }
        if k == 0 {
            let (h0, h1) = (x(1) - x(0), x(2) - x(1));
            let c = h0 / (h0 + h1);
            let w0 = -(1.0 + c) / h0;
            let w2 = -c / h1;
            ([0, 1, 2], [w0, -(w0 + w2), w2])
        } else if k >= n - 1 {
            let (a, b) = (x(n - 2) - x(n - 3), x(n - 1) - x(n - 2));
            let c = b / (a + b);
            let wl = (1.0 + c) / b;
            let wf = c / a;
            ([n - 3, n - 2, n - 1], [wf, -(wl + wf), wl])
        } else {
            let (ha, hb) = (x(k) - x(k - 1), x(k + 1) - x(k));
            let wm = -hb / ((ha + hb) * ha);
            let wp = ha / ((ha + hb) * hb);
            ([k - 1, k, k + 1], [wm, -(wm + wp), wp])
        }
    }

    /// Cell index `i`, local coordinate `t = (v - x_i) / (x_{i+1} - x_i)` (outside `[0, 1]`
    /// when extrapolating) and placement of `v`. Exact at nodes (`t` is 0 or 1 there); on
    /// evenly spaced axes no division.
    #[inline(always)]
    pub(crate) fn cell_t(
        &self,
        axis: usize,
        v: f64,
        policy: OutOfGrid,
    ) -> Result<(usize, f64, Placement), TickError> {
        let (i, v, place) = self.locate(axis, v, policy)?;
        let (x0, x1) = (self.node(i), self.node(i + 1));
        let t = if self.inv_step > 0.0 {
            even_t(v, x0, x1, self.inv_step)
        } else if v == x1 {
            1.0
        } else {
            (v - x0) / (x1 - x0)
        };
        Ok((i, t, place))
    }

    /// [`Self::cell_t`] for a `v` known to lie within the axis.
    #[inline(always)]
    pub(crate) fn cell_t_inside(&self, v: f64) -> (usize, f64) {
        let (i, x0, x1) = self.cell_nodes(v);
        let t = if self.inv_step > 0.0 {
            even_t(v, x0, x1, self.inv_step)
        } else if v == x1 {
            1.0
        } else {
            (v - x0) / (x1 - x0)
        };
        (i, t)
    }

    /// This axis for the blocked batch, when it is evenly spaced.
    pub(crate) fn even(&self) -> Option<EvenAxis<'a>> {
        (self.inv_step > 0.0).then(|| EvenAxis {
            nodes: self.nodes,
            first: self.first(),
            last: self.last(),
            inv_step: self.inv_step,
            last_cell: self.nodes.len().saturating_sub(2),
        })
    }

    /// First node coordinate.
    #[inline(always)]
    pub(crate) fn first(&self) -> f64 {
        self.node(0)
    }

    /// Last node coordinate.
    #[inline(always)]
    pub(crate) fn last(&self) -> f64 {
        self.node(self.nodes.len().saturating_sub(1))
    }

    /// The 1-D weights for coordinate `v` along this axis.
    #[inline]
    pub(crate) fn stencil(
        &self,
        axis: usize,
        v: f64,
        method: Interpolation,
        policy: OutOfGrid,
    ) -> Result<(Stencil, Placement), TickError> {
        let (i, t, place) = self.cell_t(axis, v, policy)?;
        // The coordinate actually evaluated (clamped if so asked).
        let v = self.node(i) + t * (self.node(i + 1) - self.node(i));
        let h = self.node(i + 1) - self.node(i);
        let mut s = Stencil {
            base: i,
            len: 2,
            w: [1.0 - t, t, 0.0, 0.0],
        };
        if method == Interpolation::Bilinear {
            // Linear in the cell; outside the grid this is the boundary cell's line.
            return Ok((s, place));
        }
        let n = self.nodes.len();
        s.base = i.saturating_sub(1).min(n.saturating_sub(4));
        s.len = n.min(4);
        s.w = [0.0; 4];
        if !(0.0..=1.0).contains(&t) {
            // Extrapolation: C1 continuation with the boundary node's value and slope.
            let b = if t < 0.0 { i } else { i + 1 };
            let dist = v - self.node(b);
            s.add(b, 1.0);
            let (idx, w) = self.slope_weights(b);
            for (k, wk) in idx.iter().zip(w.iter()) {
                s.add(*k, dist * wk);
            }
            return Ok((s, place));
        }
        // Cubic Hermite on [x_i, x_{i+1}] with finite-difference node slopes.
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        s.add(i, h00);
        s.add(i + 1, h01);
        for (node, coef) in [(i, h * h10), (i + 1, h * h11)] {
            let (idx, w) = self.slope_weights(node);
            for (k, wk) in idx.iter().zip(w.iter()) {
                s.add(*k, coef * wk);
            }
        }
        Ok((s, place))
    }
}

/// The cell estimate on an evenly spaced axis, `(v - first) / step`, within the cells (a
/// saturating float->int cast: negative and NaN become 0).
#[inline(always)]
fn even_estimate(v: f64, first: f64, inv_step: f64, last_cell: usize) -> usize {
    // Through i64, the same value as `as usize` for every input (a negative or NaN estimate
    // is 0 either way, one past 2^63 the last cell either way) in half the instructions: x86
    // has the signed conversion, the unsigned one takes a second conversion and a select.
    let estimate = ((v - first) * inv_step) as i64;
    (estimate.max(0) as usize).min(last_cell)
}

/// The local coordinate of `v` in the cell `[lo, hi]` of an evenly spaced axis (exactly 1 at
/// its upper node).
#[inline(always)]
fn even_t(v: f64, lo: f64, hi: f64, inv_step: f64) -> f64 {
    if v == hi { 1.0 } else { (v - lo) * inv_step }
}

/// An evenly spaced axis as the blocked batch reads it (`super::batch`): its ends and cell
/// count loaded once.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EvenAxis<'a> {
    pub(super) nodes: &'a [f64],
    pub(super) first: f64,
    pub(super) last: f64,
    pub(super) inv_step: f64,
    pub(super) last_cell: usize,
}

/// The first node and inverse step of an evenly spaced axis: what the owning map keeps for
/// its single query, which reads nothing else of the axis but its nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EvenStart {
    first: f64,
    inv_step: f64,
}

impl EvenStart {
    /// The cell of `v` among `nodes` (the axis this was taken from) and its local coordinate
    /// `(v - lo) / step`, when `v` lies in `[lo, hi)` of the estimated cell: the same cell and
    /// bits as [`Axis::cell_t_inside`], which gives that cell whenever `v` lies in it. `None`
    /// for `v` at that cell's upper node (the last node, or one whose estimate rounded down),
    /// outside the axis, or NaN, which the view's path answers. Leaving the upper node out
    /// drops the select that makes `t` exactly 1 there, and leaving the estimate unclamped
    /// lets the node pair's bounds check refuse an estimate past the last cell (a third fewer
    /// instructions than [`EvenAxis::cell_t`], and a shorter chain to `t`).
    #[inline(always)]
    pub(crate) fn cell_t_below_upper(self, nodes: &[f64], v: f64) -> Option<(usize, f64)> {
        // Negative and NaN estimates are 0 (the cast saturates), so `i + 2` cannot wrap.
        let i = (((v - self.first) * self.inv_step) as i64).max(0) as usize;
        let &[lo, hi] = nodes.get(i..i + 2)? else {
            return None;
        };
        ((v >= lo) & (v < hi)).then_some((i, (v - lo) * self.inv_step))
    }
}

impl EvenAxis<'_> {
    /// What the owning map keeps of this axis for its single query.
    pub(crate) fn start(&self) -> EvenStart {
        EvenStart {
            first: self.first,
            inv_step: self.inv_step,
        }
    }

    /// The cell of `v` and its local coordinate, as [`Axis::cell_t_inside`], and whether `v`
    /// is inside the axis and needs no rounding correction: computed without a branch on
    /// the data, the correction left to the single query's path for the rows it refuses.
    #[inline(always)]
    pub(crate) fn cell_t(&self, v: f64) -> (usize, f64, bool) {
        let i = even_estimate(v, self.first, self.inv_step, self.last_cell);
        let (lo, hi) = match self.nodes.get(i..i + 2) {
            Some(&[lo, hi]) => (lo, hi),
            _ => (f64::NAN, f64::NAN),
        };
        // Inside the cell is inside the axis (its nodes lie between the axis' ends); NaN is
        // neither.
        let ok = (v >= lo) & (v <= hi);
        (i, even_t(v, lo, hi, self.inv_step), ok)
    }
}

/// Up to 4 consecutive node weights along one axis, starting at node `base`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stencil {
    pub base: usize,
    pub len: usize,
    pub w: [f64; 4],
}

impl Stencil {
    #[inline]
    fn add(&mut self, node: usize, weight: f64) {
        if let Some(slot) = node.checked_sub(self.base).and_then(|k| self.w.get_mut(k)) {
            *slot += weight;
        }
    }
}
