//! The bilinear batch on evenly spaced axes four rows at a time in AVX2 registers (x86-64
//! with `std`, chosen at run time): one row per lane, from the cell lookup to the stored
//! displacement, with no per-row branch. The blocked kernel of `super::batch` left the
//! cell lookup scalar (the float-to-index conversion and the node reads did not vectorise)
//! and the blend one row at a time: 12 ns a point on one core for the paper's 2 x 2 map.
//!
//! Every lane performs the single query's operations in its order (Eq. 14's weights from
//! `cell_t`, then `sum_n w_n * ((sum_f s[d][f] * F[f]) + o[d])` from 0), with no fused
//! multiply-add, so every row gives the bits of [`ComplianceMapView::displacement_with`]. A
//! group with a row it cannot vouch for (outside the grid, not finite, at a node's rounding
//! edge, a non-finite result) is redone one row at a time by `super::batch`'s path.

use core::arch::x86_64::{__m128d, __m128i, __m256d, _CMP_EQ_OQ, _CMP_GE_OQ, _CMP_LE_OQ};

use pulp::cast;
use pulp::x86::V3;

use super::batch_row::{Row, one_row};
use super::grid::EvenAxis;
use super::interp::{BatchError, BatchSummary};
use super::kernel::packed_block;
use super::{ComplianceMapView, QueryOptions};

/// Lane `l` of a group holds row `ROW_OF_LANE[l]`: the order in which unpacking two
/// interleaved pairs of rows leaves them.
const ROW_OF_LANE: [usize; 4] = [0, 2, 1, 3];

/// The batch of `super::batch`'s `batch_bilinear_even` for positions of stride 2, in
/// groups of four rows; the last rows and declined groups one at a time. `B` is the packed
/// block, `ND * (NF + 1)` (`None` otherwise): the length of the kernel's arrays.
#[allow(clippy::too_many_arguments)] // reason: one private kernel, the batch's own arguments
pub(super) fn batch<const ND: usize, const NF: usize, const B: usize>(
    simd: V3,
    view: &ComplianceMapView<'_>,
    axes: (EvenAxis<'_>, EvenAxis<'_>),
    positions: &[f64],
    forces: &[f64],
    out: &mut [f64],
    options: QueryOptions,
) -> Option<Result<BatchSummary, BatchError>> {
    if B != packed_block(ND, NF) {
        return None;
    }
    /// The loop as pulp's closure, compiled with AVX2 enabled.
    struct Run<'a, 'v, const ND: usize, const NF: usize, const B: usize> {
        simd: V3,
        view: &'a ComplianceMapView<'v>,
        axes: (EvenAxis<'a>, EvenAxis<'a>),
        positions: &'a [f64],
        forces: &'a [f64],
        out: &'a mut [f64],
        options: QueryOptions,
    }
    impl<const ND: usize, const NF: usize, const B: usize> pulp::NullaryFnOnce
        for Run<'_, '_, ND, NF, B>
    {
        type Output = Result<BatchSummary, BatchError>;
        #[inline(always)]
        fn call(self) -> Self::Output {
            let simd = self.simd;
            let (view, axes, options) = (self.view, &self.axes, self.options);
            let tables = (Tables::new(simd, &axes.0), Tables::new(simd, &axes.1));
            let mut summary = BatchSummary::default();
            let groups = self
                .positions
                .chunks(8)
                .zip(self.forces.chunks(4 * NF))
                .zip(self.out.chunks_mut(4 * ND));
            for (g, ((p, f), o)) in groups.enumerate() {
                if group::<ND, NF, B>(simd, view, (&tables.0, &tables.1), p, f, o) {
                    summary.inside += 4;
                    continue;
                }
                let rows = p.chunks_exact(2).zip(f.chunks_exact(NF));
                for (k, ((p, f), o)) in rows.zip(o.chunks_exact_mut(ND)).enumerate() {
                    let row = Row { p, stride: 2, f, o };
                    let place = one_row::<ND, NF>(view, (&axes.0, &axes.1), row, options).map_err(
                        |error| BatchError {
                            row: 4 * g + k,
                            error,
                        },
                    )?;
                    if let Some(place) = place {
                        summary.count(place);
                    }
                }
            }
            Ok(summary)
        }
    }
    Some(simd.vectorize(Run::<ND, NF, B> {
        simd,
        view,
        axes,
        positions,
        forces,
        out,
        options,
    }))
}

/// Four rows (`p` 8 values, `f` `4 * NF`, `o` `4 * ND`), one per lane: `false`, with `o`
/// untouched, when a row is not inside the grid with finite input and result (or the
/// group is short), for the caller to redo row by row.
#[inline(always)]
fn group<const ND: usize, const NF: usize, const B: usize>(
    simd: V3,
    view: &ComplianceMapView<'_>,
    (along_x, along_y): (&Tables<'_>, &Tables<'_>),
    p: &[f64],
    f: &[f64],
    o: &mut [f64],
) -> bool {
    let avx = simd.avx;
    let Ok(p) = <&[f64; 8]>::try_from(p) else {
        return false;
    };
    if o.len() != 4 * ND {
        return false;
    }
    let [p0, p1, p2, p3, p4, p5, p6, p7] = *p;
    let (a, b): (__m256d, __m256d) = (cast([p0, p1, p2, p3]), cast([p4, p5, p6, p7]));
    let (px, py) = (avx._mm256_unpacklo_pd(a, b), avx._mm256_unpackhi_pd(a, b));
    let Some(fl) = force_lanes::<NF>(simd, f) else {
        return false;
    };
    let zero = avx._mm256_setzero_pd();
    let (add, mul) = (
        |a, b| avx._mm256_add_pd(a, b),
        |a, b| avx._mm256_mul_pd(a, b),
    );
    // NaN and infinities make this NaN; finite values make it exactly 0.
    let probe = fl.iter().fold(add(mul(px, zero), mul(py, zero)), |a, &v| {
        add(a, mul(v, zero))
    });
    let (i, tx, ok_x) = along_x.cells(simd, px);
    let (j, ty, ok_y) = along_y.cells(simd, py);
    let finite = avx._mm256_cmp_pd::<_CMP_EQ_OQ>(probe, zero);
    let ok = avx._mm256_and_pd(avx._mm256_and_pd(ok_x, ok_y), finite);
    if avx._mm256_movemask_pd(ok) != 0b1111 {
        return false;
    }
    let one = avx._mm256_set1_pd(1.0);
    let (ux, uy) = (avx._mm256_sub_pd(one, tx), avx._mm256_sub_pd(one, ty));
    let w = [mul(ux, uy), mul(ux, ty), mul(tx, uy), mul(tx, ty)];
    // Each lane's first node times the block: near pair at `base`, far pair `ny` nodes on
    // (32-bit: the dispatcher keeps the packed table below 2^31 values).
    let (sse2, sse41) = (simd.sse2, simd.sse4_1);
    let ny = view.y.nodes.len();
    let n00 = sse2._mm_add_epi32(sse41._mm_mullo_epi32(i, sse2._mm_set1_epi32(ny as i32)), j);
    let base: [i32; 4] = cast(sse41._mm_mullo_epi32(n00, sse2._mm_set1_epi32(B as i32)));
    let pair = |start: usize| -> Option<(&[f64; B], &[f64; B])> {
        let (a, b) = view.packed.get(start..start + 2 * B)?.split_at(B);
        Some((a.try_into().ok()?, b.try_into().ok()?))
    };
    let mut nodes: [[&[f64; B]; 4]; 4] = [[&[0.0; B]; 4]; 4];
    for (l, base) in base.into_iter().enumerate() {
        let base = usize::try_from(base).unwrap_or(usize::MAX / 2);
        let (Some((n0, n1)), Some((n2, n3))) = (pair(base), pair(base + ny * B)) else {
            return false; // unreachable: the cells are inside the grid
        };
        for (node, blk) in nodes.iter_mut().zip([n0, n1, n2, n3]) {
            if let Some(slot) = node.get_mut(l) {
                *slot = blk;
            }
        }
    }
    let mut acc = [zero; ND];
    for (blocks, w) in nodes.into_iter().zip(w) {
        let col = columns::<B>(simd, blocks);
        let (slopes, offsets) = col.split_at(ND * NF);
        for ((a, s), o) in acc.iter_mut().zip(slopes.chunks_exact(NF)).zip(offsets) {
            let line = s
                .iter()
                .zip(&fl)
                .fold(zero, |l, (&s, &f)| add(l, mul(s, f)));
            *a = add(*a, mul(w, add(line, *o)));
        }
    }
    let check = acc.iter().fold(zero, |c, &a| add(c, mul(a, zero)));
    if avx._mm256_movemask_pd(avx._mm256_cmp_pd::<_CMP_EQ_OQ>(check, zero)) != 0b1111 {
        return false;
    }
    store::<ND>(simd, acc, o);
    true
}

/// The forces of four rows, one lane-vector per force axis, lanes in `ROW_OF_LANE` order.
#[inline(always)]
fn force_lanes<const NF: usize>(simd: V3, f: &[f64]) -> Option<[__m256d; NF]> {
    let avx = simd.avx;
    if NF == 2 {
        let [f0, f1, f2, f3, f4, f5, f6, f7] = *<&[f64; 8]>::try_from(f).ok()?;
        let (a, b): (__m256d, __m256d) = (cast([f0, f1, f2, f3]), cast([f4, f5, f6, f7]));
        let pair = [avx._mm256_unpacklo_pd(a, b), avx._mm256_unpackhi_pd(a, b)];
        let mut out = [avx._mm256_setzero_pd(); NF];
        out.iter_mut().zip(pair).for_each(|(o, v)| *o = v);
        return Some(out);
    }
    if f.len() != 4 * NF {
        return None;
    }
    let mut out = [avx._mm256_setzero_pd(); NF];
    for (q, o) in out.iter_mut().enumerate() {
        let at = |row: usize| f.get(row * NF + q).copied().unwrap_or(f64::NAN);
        *o = cast(ROW_OF_LANE.map(at));
    }
    Some(out)
}

/// Axes of at most this many cells take their nodes from registers (`Tables`); longer ones
/// read them from memory lane by lane.
const MAX_TABLE_CELLS: usize = 32;

/// An evenly spaced axis held in registers for a batch: its constants, and its nodes as
/// tables of four cells, `lo[t]` the lower nodes of cells `4t..4t + 4` and `hi[t]` their
/// upper nodes (NaN past the last node), for a lookup by lane permutes.
struct Tables<'a> {
    axis: &'a EvenAxis<'a>,
    first: __m256d,
    last: __m256d,
    inv: __m256d,
    last_cell: __m256d,
    /// Tables in use; 0 for an axis longer than [`MAX_TABLE_CELLS`] cells.
    count: usize,
    lo: [__m256d; MAX_TABLE_CELLS / 4],
    hi: [__m256d; MAX_TABLE_CELLS / 4],
}

impl<'a> Tables<'a> {
    #[inline(always)]
    fn new(simd: V3, axis: &'a EvenAxis<'a>) -> Self {
        let avx = simd.avx;
        let cells = axis.last_cell + 1;
        let count = if cells <= MAX_TABLE_CELLS {
            cells.div_ceil(4)
        } else {
            0
        };
        let node = |k: usize| axis.nodes.get(k).copied().unwrap_or(f64::NAN);
        let table = |t: usize, shift: usize| -> __m256d {
            cast([0, 1, 2, 3].map(|k| node(4 * t + k + shift)))
        };
        let mut lo = [avx._mm256_setzero_pd(); MAX_TABLE_CELLS / 4];
        let mut hi = lo;
        for (t, (lo, hi)) in lo.iter_mut().zip(hi.iter_mut()).enumerate().take(count) {
            (*lo, *hi) = (table(t, 0), table(t, 1));
        }
        Self {
            axis,
            first: avx._mm256_set1_pd(axis.first),
            last: avx._mm256_set1_pd(axis.last),
            inv: avx._mm256_set1_pd(axis.inv_step),
            last_cell: avx._mm256_set1_pd(axis.last_cell as f64),
            count,
            lo,
            hi,
        }
    }

    /// The cells' lower and upper nodes: `cells` in the low 32 bits of each 64-bit lane,
    /// `clamped` the same cells as floats.
    #[inline(always)]
    fn nodes(&self, simd: V3, cells: __m128i, clamped: __m256d) -> (__m256d, __m256d) {
        let (avx, avx2) = (simd.avx, simd.avx2);
        if self.count == 0 {
            let c: [i32; 4] = cast(cells);
            let node = |k: i32| {
                let k = usize::try_from(k).unwrap_or(usize::MAX);
                self.axis.nodes.get(k).copied().unwrap_or(f64::NAN)
            };
            return (cast(c.map(node)), cast(c.map(|k| node(k + 1))));
        }
        // Lane l's f64 is the pair of 32-bit entries (2c, 2c + 1) of a table; the permute
        // reads the index modulo 8, so one index serves every table.
        let c = avx2._mm256_cvtepu32_epi64(cells);
        let twice = avx2._mm256_add_epi64(c, c);
        let next = avx2._mm256_add_epi64(twice, avx._mm256_set1_epi64x(1));
        let idx = avx2._mm256_or_si256(twice, avx2._mm256_slli_epi64::<32>(next));
        let look = |t: __m256d| -> __m256d {
            avx._mm256_castps_pd(avx2._mm256_permutevar8x32_ps(avx._mm256_castpd_ps(t), idx))
        };
        let (mut lo, mut hi) = (look(self.lo[0]), look(self.hi[0]));
        for t in 1..self.count.min(MAX_TABLE_CELLS / 4) {
            let from = avx._mm256_cmp_pd::<_CMP_GE_OQ>(clamped, avx._mm256_set1_pd(4.0 * t as f64));
            let (Some(&tl), Some(&th)) = (self.lo.get(t), self.hi.get(t)) else {
                break;
            };
            lo = avx._mm256_blendv_pd(lo, look(tl), from);
            hi = avx._mm256_blendv_pd(hi, look(th), from);
        }
        (lo, hi)
    }

    /// Four coordinates `v`: each lane's cell (32-bit), local coordinate and whether it is
    /// inside the axis with no rounding correction needed, as `EvenAxis::cell_t`: the cell
    /// is `min(trunc((v - first) / step), last_cell)`, 0 for a negative or NaN estimate
    /// (Rust's saturating `as usize`), here clamped before the conversion.
    #[inline(always)]
    fn cells(&self, simd: V3, v: __m256d) -> (__m128i, __m256d, __m256d) {
        let avx = simd.avx;
        let estimate = avx._mm256_mul_pd(avx._mm256_sub_pd(v, self.first), self.inv);
        // `max` gives its second operand for a NaN lane: 0.
        let clamped = avx._mm256_min_pd(
            avx._mm256_max_pd(estimate, avx._mm256_setzero_pd()),
            self.last_cell,
        );
        let cells = avx._mm256_cvttpd_epi32(clamped);
        let (lo, hi) = self.nodes(simd, cells, clamped);
        let inside = avx._mm256_and_pd(
            avx._mm256_cmp_pd::<_CMP_GE_OQ>(v, self.first),
            avx._mm256_cmp_pd::<_CMP_LE_OQ>(v, self.last),
        );
        let in_cell = avx._mm256_and_pd(
            avx._mm256_cmp_pd::<_CMP_GE_OQ>(v, lo),
            avx._mm256_cmp_pd::<_CMP_LE_OQ>(v, hi),
        );
        let t = avx._mm256_blendv_pd(
            avx._mm256_mul_pd(avx._mm256_sub_pd(v, lo), self.inv),
            avx._mm256_set1_pd(1.0),
            avx._mm256_cmp_pd::<_CMP_EQ_OQ>(v, hi),
        );
        (cells, t, avx._mm256_and_pd(inside, in_cell))
    }
}

/// Four nodes' packed blocks (`blocks[l]` the node of lane `l`, `B` values each) as one
/// lane-vector per value: 4 x 4 transposes, then a pair, then a single value.
#[inline(always)]
fn columns<const B: usize>(simd: V3, blocks: [&[f64; B]; 4]) -> [__m256d; B] {
    let avx = simd.avx;
    let b = B;
    let mut col = [avx._mm256_setzero_pd(); B];
    let mut k = 0;
    while k + 4 <= b {
        let [r0, r1, r2, r3] = blocks.map(|s| -> __m256d {
            let run = s.get(k..k + 4).and_then(|r| <[f64; 4]>::try_from(r).ok());
            cast(run.unwrap_or([f64::NAN; 4]))
        });
        let (t0, t1) = (
            avx._mm256_unpacklo_pd(r0, r1),
            avx._mm256_unpackhi_pd(r0, r1),
        );
        let (t2, t3) = (
            avx._mm256_unpacklo_pd(r2, r3),
            avx._mm256_unpackhi_pd(r2, r3),
        );
        let four = [
            avx._mm256_permute2f128_pd::<0x20>(t0, t2),
            avx._mm256_permute2f128_pd::<0x20>(t1, t3),
            avx._mm256_permute2f128_pd::<0x31>(t0, t2),
            avx._mm256_permute2f128_pd::<0x31>(t1, t3),
        ];
        if let Some(c) = col.get_mut(k..k + 4) {
            c.iter_mut().zip(four).for_each(|(c, v)| *c = v);
        }
        k += 4;
    }
    if k + 2 <= b {
        let [r0, r1, r2, r3] = blocks.map(|s| -> __m128d {
            let run = s.get(k..k + 2).and_then(|r| <[f64; 2]>::try_from(r).ok());
            cast(run.unwrap_or([f64::NAN; 2]))
        });
        // [r0 | r2] and [r1 | r3], then their low and high halves interleaved.
        let (x, y) = (avx._mm256_set_m128d(r2, r0), avx._mm256_set_m128d(r3, r1));
        if let Some(c) = col.get_mut(k..k + 2) {
            c.iter_mut()
                .zip([avx._mm256_unpacklo_pd(x, y), avx._mm256_unpackhi_pd(x, y)])
                .for_each(|(c, v)| *c = v);
        }
        k += 2;
    }
    if k < b
        && let Some(c) = col.get_mut(k)
    {
        *c = cast(blocks.map(|s| s.get(k).copied().unwrap_or(f64::NAN)));
    }
    col
}

/// Writes the four rows' displacements (one lane-vector per axis) row by row into `o`.
#[inline(always)]
fn store<const ND: usize>(simd: V3, acc: [__m256d; ND], o: &mut [f64]) {
    let avx = simd.avx;
    if let ([d0, d1], Ok(o)) = (acc.as_slice(), <&mut [f64; 8]>::try_from(&mut *o)) {
        // Rows 0 and 1 in the low halves, 2 and 3 in the high ones.
        let rows01: [f64; 4] = cast(avx._mm256_unpacklo_pd(*d0, *d1));
        let rows23: [f64; 4] = cast(avx._mm256_unpackhi_pd(*d0, *d1));
        let [a, b, c, d] = rows01;
        let [e, f, g, h] = rows23;
        *o = [a, b, c, d, e, f, g, h];
        return;
    }
    for (d, a) in acc.into_iter().enumerate() {
        let lanes: [f64; 4] = cast(a);
        for (row, v) in ROW_OF_LANE.into_iter().zip(lanes) {
            if let Some(slot) = o.get_mut(row * ND + d) {
                *slot = v;
            }
        }
    }
}
