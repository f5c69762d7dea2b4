//! The arithmetic of a query: node values (Eq. 9-10) blended with 2-D weights (Eq. 14, or the
//! cubic Hermite option), with kernels specialised for the common axis counts.
//!
//! Every path — single query, batch, the fixed-size kernels, the generic one, the packed and
//! the plain coefficient layout — computes each node value as
//! `v[d] = (sum_f slope[d][f] * F[f]) + (sum_f offset[d][f])` and the result as
//! `out[d] = sum_n w_n * v_n[d]`, in the same order, so they agree bit for bit.
//!
//! Packed layout (built by the owning [`super::ComplianceMap`]): per node, the `nd * nf`
//! slopes then the `nd` offset sums, nodes in the order `i * ny + j`. The two nodes of a cell
//! that share `i` are adjacent, so a bilinear query reads two contiguous runs of
//! `2 * nd * (nf + 1)` values (96 bytes, two cache lines or fewer, for the paper's 2 x 2).

use super::ComplianceMapView;
use super::MAX_AXES;
use super::grid::EvenStart;

/// `$fixed!(nd, nf)` for the shapes with fixed-size kernels (the paper's 2 x 2, 3-D and 6-D
/// maps, and a displacement field's map of one unit load), `$other` for any other shape.
macro_rules! fixed_shapes {
    ($shape:expr, $fixed:ident, $other:expr) => {
        match $shape {
            (2, 2) => $fixed!(2, 2),
            (3, 3) => $fixed!(3, 3),
            (6, 6) => $fixed!(6, 6),
            (2, 1) => $fixed!(2, 1),
            (3, 1) => $fixed!(3, 1),
            (6, 1) => $fixed!(6, 1),
            _ => $other,
        }
    };
}
pub(super) use fixed_shapes;

/// Values per node in the packed layout.
#[inline(always)]
pub(crate) const fn packed_block(n_disp: usize, n_force: usize) -> usize {
    n_disp * (n_force + 1)
}

/// Sum of one displacement axis' offsets over the force axes, in the kernels' order.
#[inline(always)]
fn offset_sum(offsets: &[f64]) -> f64 {
    offsets.iter().fold(0.0, |a, o| a + o)
}

/// Packs plain `slopes` and `offsets` (layout of [`ComplianceMapView`]) node by node into
/// `out` (`nodes * packed_block(nd, nf)` values).
#[cfg(feature = "alloc")]
pub(crate) fn pack(
    n_disp: usize,
    n_force: usize,
    slopes: &[f64],
    offsets: &[f64],
) -> alloc::vec::Vec<f64> {
    let block = n_disp * n_force;
    let nodes = slopes.len().checked_div(block).unwrap_or(0);
    let mut out = alloc::vec::Vec::with_capacity(nodes * packed_block(n_disp, n_force));
    for (s, o) in slopes.chunks_exact(block).zip(offsets.chunks_exact(block)) {
        out.extend_from_slice(s);
        out.extend(o.chunks_exact(n_force).map(offset_sum));
    }
    out
}

impl ComplianceMapView<'_> {
    /// Node `node`'s displacement under `f` (Eq. 9-10), fixed sizes.
    #[inline(always)]
    fn node_value<const ND: usize, const NF: usize>(
        &self,
        node: usize,
        f: &[f64; NF],
    ) -> [f64; ND] {
        let mut v = [0.0; ND];
        let line =
            |s_row: &[f64]| -> f64 { s_row.iter().zip(f).fold(0.0, |a, (s, fk)| a + s * fk) };
        if self.packed.is_empty() {
            let start = node * ND * NF;
            let (Some(s), Some(o)) = (
                self.slopes.get(start..start + ND * NF),
                self.offsets.get(start..start + ND * NF),
            ) else {
                return v; // unreachable for a validated view
            };
            for ((v_d, s_row), o_row) in
                v.iter_mut().zip(s.chunks_exact(NF)).zip(o.chunks_exact(NF))
            {
                *v_d = line(s_row) + offset_sum(o_row);
            }
        } else {
            let b = packed_block(ND, NF);
            let Some(blk) = self.packed.get(node * b..node * b + b) else {
                return v; // unreachable for a validated view
            };
            let (s, o) = blk.split_at(ND * NF);
            for ((v_d, s_row), o_d) in v.iter_mut().zip(s.chunks_exact(NF)).zip(o) {
                *v_d = line(s_row) + o_d;
            }
        }
        v
    }

    /// [`Self::node_value`] for run-time sizes, into the first `nd` entries of the result.
    #[inline]
    pub(super) fn node_value_dyn(&self, node: usize, f: &[f64]) -> [f64; MAX_AXES] {
        let (nd, nf) = (self.n_disp, self.n_force);
        let mut v = [0.0; MAX_AXES];
        let line =
            |s_row: &[f64]| -> f64 { s_row.iter().zip(f).fold(0.0, |a, (s, fk)| a + s * fk) };
        if self.packed.is_empty() {
            let start = node * nd * nf;
            let (Some(s), Some(o)) = (
                self.slopes.get(start..start + nd * nf),
                self.offsets.get(start..start + nd * nf),
            ) else {
                return v;
            };
            for ((v_d, s_row), o_row) in
                v.iter_mut().zip(s.chunks_exact(nf)).zip(o.chunks_exact(nf))
            {
                *v_d = line(s_row) + offset_sum(o_row);
            }
        } else {
            let b = packed_block(nd, nf);
            let Some(blk) = self.packed.get(node * b..node * b + b) else {
                return v;
            };
            let (s, o) = blk.split_at(nd * nf);
            for ((v_d, s_row), o_d) in v.iter_mut().zip(s.chunks_exact(nf)).zip(o) {
                *v_d = line(s_row) + o_d;
            }
        }
        v
    }

    /// `sum_n w_n * v_n` over the given nodes, fixed sizes.
    #[inline(always)]
    pub(super) fn blend_fixed<const ND: usize, const NF: usize>(
        &self,
        nodes: &[usize],
        weights: &[f64],
        f: &[f64; NF],
    ) -> [f64; ND] {
        let mut acc = [0.0; ND];
        for (node, w) in nodes.iter().zip(weights) {
            let v = self.node_value::<ND, NF>(*node, f);
            for (a, v_d) in acc.iter_mut().zip(&v) {
                *a += w * v_d;
            }
        }
        acc
    }

    /// The blend for any sizes into `out` (`nd` entries), dispatching to the fixed kernels
    /// for the common shapes (the paper's 2 x 2, 3-D, 6-D).
    #[inline(always)]
    pub(super) fn blend(&self, nodes: &[usize], weights: &[f64], force: &[f64], out: &mut [f64]) {
        macro_rules! fixed {
            ($nd:literal, $nf:literal) => {
                if let (Ok(f), Ok(o)) = (
                    <&[f64; $nf]>::try_from(force),
                    <&mut [f64; $nd]>::try_from(&mut *out),
                ) {
                    *o = self.blend_fixed::<$nd, $nf>(nodes, weights, f);
                    return;
                }
            };
        }
        fixed_shapes!((self.n_disp, self.n_force), fixed, {});
        let mut acc = [0.0; MAX_AXES];
        for (node, w) in nodes.iter().zip(weights) {
            let v = self.node_value_dyn(*node, force);
            for (a, v_d) in acc.iter_mut().zip(&v).take(self.n_disp) {
                *a += w * v_d;
            }
        }
        out.iter_mut().zip(&acc).for_each(|(o, a)| *o = *a);
    }

    /// Bilinear weights and nodes of cell `(i, j)` at local coordinates `(tx, ty)` (Eq. 14:
    /// `(x2 - x)(y2 - y)`, `(x2 - x)(y - y1)`, ... over `(x2 - x1)(y2 - y1)`).
    #[inline(always)]
    pub(super) fn bilinear_stencil(
        &self,
        i: usize,
        j: usize,
        tx: f64,
        ty: f64,
    ) -> ([usize; 4], [f64; 4]) {
        let ny = self.y.nodes.len();
        let n00 = i * ny + j;
        let (ux, uy) = (1.0 - tx, 1.0 - ty);
        (
            [n00, n00 + 1, n00 + ny, n00 + ny + 1],
            [ux * uy, ux * ty, tx * uy, tx * ty],
        )
    }

    /// The bilinear query for finite input inside the grid, fixed sizes: `None` when the
    /// position is outside or any input is not finite, so the caller takes the general path
    /// (which names the error or applies the out-of-grid policy). Gives the same bits as
    /// the general path.
    #[inline(always)]
    pub(super) fn bilinear_inside<const ND: usize, const NF: usize>(
        &self,
        [px, py]: [f64; 2],
        f: &[f64; NF],
    ) -> Option<[f64; ND]> {
        // NaN and infinities make this NaN; finite values make it exactly 0.
        let probe = f.iter().fold(px * 0.0 + py * 0.0, |a, v| a + v * 0.0);
        let inside = px >= self.x.first()
            && px <= self.x.last()
            && py >= self.y.first()
            && py <= self.y.last();
        if probe != 0.0 || !inside {
            return None;
        }
        let (i, tx) = self.x.cell_t_inside(px);
        let (j, ty) = self.y.cell_t_inside(py);
        let (nodes, weights) = self.bilinear_stencil(i, j, tx, ty);
        Some(self.blend_fixed::<ND, NF>(&nodes, &weights, f))
    }
}

/// [`ComplianceMapView::blend_fixed`] over a bilinear cell's nodes `n00, n00 + 1, n00 + ny,
/// n00 + ny + 1` of a `packed` layout, reading the two runs of adjacent nodes as two slices
/// (two bounds checks instead of four). Same bits.
#[inline(always)]
pub(super) fn blend_cell<const ND: usize, const NF: usize>(
    packed: &[f64],
    n00: usize,
    ny: usize,
    weights: &[f64; 4],
    f: &[f64; NF],
) -> Option<[f64; ND]> {
    let b = packed_block(ND, NF);
    // From the cell's first node on, then the two runs: no range that could wrap around.
    let cell = packed.get(n00 * b..)?;
    let far = cell.get(ny * b..)?.get(..2 * b)?;
    let near = cell.get(..2 * b)?;
    let (n0, n1) = near.split_at(b);
    let (n2, n3) = far.split_at(b);
    let mut acc = [0.0; ND];
    for (blk, w) in [n0, n1, n2, n3].into_iter().zip(weights) {
        let (s, o) = blk.split_at(ND * NF);
        for ((a, s_row), o_d) in acc.iter_mut().zip(s.chunks_exact(NF)).zip(o) {
            // From the first product rather than from 0.0 as the other paths: the two sums
            // differ at most in the sign of a zero, which `+ o_d`, `w *` and the accumulator
            // (from +0.0, so never -0.0) do not carry into the result. Same bits.
            let mut terms = s_row.iter().zip(f).map(|(s, fk)| s * fk);
            let first = terms.next().unwrap_or(0.0);
            let line = terms.fold(first, |a, t| a + t);
            *a += w * (line + o_d);
        }
    }
    Some(acc)
}

/// The bilinear query on an evenly spaced grid of `packed` coefficients for finite input
/// below the upper nodes of its estimated cell ([`EvenStart::cell_t_below_upper`]): the same
/// cell, weights and blend as [`ComplianceMapView::bilinear_inside`], so the same bits;
/// `None` otherwise, for the view's path (which takes the upper nodes, corrects the cell,
/// names the error or applies the out-of-grid policy). The owning map's single query: no
/// view to build, the axes' ends kept, the inside test folded into the cell's.
#[inline(always)]
pub(super) fn even_bilinear<const ND: usize, const NF: usize>(
    packed: &[f64],
    [x, y]: [&[f64]; 2],
    [ex, ey]: [EvenStart; 2],
    [px, py]: [f64; 2],
    f: &[f64; NF],
) -> Option<[f64; ND]> {
    // A NaN or infinite force makes this NaN; finite forces make it exactly 0. A NaN or
    // infinite position lies in no cell.
    let probe = f.iter().fold(0.0, |a, v| a + v * 0.0);
    let (i, tx) = ex.cell_t_below_upper(x, px)?;
    let (j, ty) = ey.cell_t_below_upper(y, py)?;
    if probe != 0.0 {
        return None;
    }
    let ny = y.len();
    let (ux, uy) = (1.0 - tx, 1.0 - ty);
    let weights = [ux * uy, ux * ty, tx * uy, tx * ty];
    blend_cell::<ND, NF>(packed, i * ny + j, ny, &weights, f)
}
