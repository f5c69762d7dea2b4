//! The bilinear batch on evenly spaced axes in blocks of rows: first every row's cell and
//! weights (Eq. 14) for a block, without a branch that depends on the data, then the blend
//! row by row. A row-at-a-time loop spent its time in the per-row tests of the cell lookup
//! (inside, finite, the rounding correction), each a branch the next row's work waited on;
//! the first phase computes them for a whole block as plain arithmetic and a mask.
//!
//! Every row gives the bits of a single query ([`ComplianceMapView::displacement_with`]):
//! the first phase repeats the single query's arithmetic (`cell_nodes`, `cell_t_inside`,
//! `bilinear_stencil`), and a row it cannot vouch for (outside the grid, not finite, at a
//! node coordinate's rounding edge, a non-finite result) takes the single query's path.
//!
//! On x86-64 with AVX2 (and `std`), positions of stride 2 (the Python binding's layout) go
//! four rows at a time through `super::batch_avx2` instead; these blocks serve the other
//! CPUs, the no_std build and positions with a z column.

use super::batch_row::{Row, cell, finish_row};
use super::grid::EvenAxis;
use super::interp::{BatchError, BatchSummary};
use super::{ComplianceMapView, QueryOptions};

/// Rows per block: the first phase's results (6 values a row) stay in L1 (3 KB).
const BLOCK: usize = 64;

impl ComplianceMapView<'_> {
    /// The bilinear batch on evenly spaced axes, fixed sizes: AVX2 lanes where they apply,
    /// else blocks; `None` when an axis is uneven or the view has no packed coefficients
    /// (the caller then goes row by row).
    pub(super) fn batch_bilinear_even<const ND: usize, const NF: usize>(
        &self,
        positions: &[f64],
        stride: usize,
        forces: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Option<Result<BatchSummary, BatchError>> {
        let (ex, ey) = (self.x.even()?, self.y.even()?);
        if self.packed.is_empty() {
            return None;
        }
        // The lanes compute node offsets in 32 bits.
        #[cfg(all(feature = "std", target_arch = "x86_64"))]
        if stride == 2
            && i32::try_from(self.packed.len()).is_ok()
            && let Some(simd) = pulp::x86::V3::try_new()
        {
            macro_rules! lanes {
                ($b:literal) => {
                    super::batch_avx2::batch::<ND, NF, $b>(
                        simd,
                        self,
                        (ex, ey),
                        positions,
                        forces,
                        out,
                        options,
                    )
                };
            }
            // The packed block of the batch's fixed shapes: 2 x 2, 3 x 3, 6 x 6.
            let lanes = match super::kernel::packed_block(ND, NF) {
                6 => lanes!(6),
                12 => lanes!(12),
                42 => lanes!(42),
                _ => None,
            };
            if lanes.is_some() {
                return lanes;
            }
        }
        Some(even_blocks::<ND, NF>(
            self, ex, ey, positions, stride, forces, out, options,
        ))
    }
}

/// The blocks, compiled once per instruction set and chosen at run time (with `std`; the
/// build's own target without it): AVX2 and AVX-512 vectorise the first phase over rows
/// (criterion, 1e5 random points: 1.41 ms with SSE2 only, 1.16 ms dispatched).
/// FMA is enabled but never used: Rust does not fuse `a * b + c` unless asked, so every
/// version gives the same bits.
#[allow(clippy::too_many_arguments)] // reason: one private kernel, the batch's own arguments
#[cfg_attr(
    feature = "std",
    multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx2+fma", "x86_64+avx2+fma"))
)]
fn even_blocks<const ND: usize, const NF: usize>(
    view: &ComplianceMapView<'_>,
    ex: EvenAxis<'_>,
    ey: EvenAxis<'_>,
    positions: &[f64],
    stride: usize,
    forces: &[f64],
    out: &mut [f64],
    options: QueryOptions,
) -> Result<BatchSummary, BatchError> {
    let ny = view.y.nodes.len();
    let mut summary = BatchSummary::default();
    let mut node = [0usize; BLOCK];
    let mut weights = [[0.0f64; 4]; BLOCK];
    let mut fast = [false; BLOCK];
    let rows = positions.chunks(stride * BLOCK);
    let blocks = rows
        .zip(forces.chunks(NF * BLOCK))
        .zip(out.chunks_mut(ND * BLOCK));
    for (b, ((pb, fb), ob)) in blocks.enumerate() {
        // Phase 1: cells, weights and the mask, for every row of the block.
        let cells = node.iter_mut().zip(weights.iter_mut()).zip(fast.iter_mut());
        for (((n, w), ok), (p, f)) in cells.zip(pb.chunks_exact(stride).zip(fb.chunks_exact(NF))) {
            (*n, *w, *ok) = cell(&ex, &ey, ny, p, f);
        }
        // Phase 2: the blend, rows in order (the first refused row stops the batch).
        let first_row = b * BLOCK;
        let cells = node.iter().zip(weights.iter()).zip(fast.iter());
        let rows = pb
            .chunks_exact(stride)
            .zip(fb.chunks_exact(NF))
            .zip(ob.chunks_exact_mut(ND));
        for (k, (((n, w), ok), ((p, f), o))) in cells.zip(rows).enumerate() {
            let row = first_row + k;
            let cell = (*n, w, *ok);
            let place = finish_row::<ND, NF>(view, cell, Row { p, stride, f, o }, options)
                .map_err(|error| BatchError { row, error })?;
            if let Some(place) = place {
                summary.count(place);
            }
        }
    }
    Ok(summary)
}
