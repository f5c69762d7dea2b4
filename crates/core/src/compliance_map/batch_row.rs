//! One row of the bilinear batch on evenly spaced axes: its cell and weights (Eq. 14),
//! computed without a data-dependent branch, and its blend, or the single query's path for a
//! row the mask cannot vouch for. Shared by the blocks (`super::batch`) and the AVX2 lanes
//! (`super::batch_avx2`).

use super::ComplianceMapView;
use super::QueryOptions;
use super::grid::EvenAxis;
use super::interp::ignored_entries;
use crate::error::{Placement, TickError};

/// One row of a batch: its position (`stride` values, x and y first), force and output.
pub(super) struct Row<'r> {
    pub p: &'r [f64],
    pub stride: usize,
    pub f: &'r [f64],
    pub o: &'r mut [f64],
}

/// One row whose cell, weights and mask (`cell`: first node, Eq. 14 weights, inside and
/// finite) are known: the packed blend when the mask allows and the result is finite, the
/// single query's path otherwise. `Ok(None)` only for a row too short to hold x and y
/// (unreachable: stride >= 2).
#[inline(always)]
pub(super) fn finish_row<const ND: usize, const NF: usize>(
    view: &ComplianceMapView<'_>,
    (n, w, ok): (usize, &[f64; 4], bool),
    Row { p, stride, f, o }: Row<'_>,
    options: QueryOptions,
) -> Result<Option<Placement>, TickError> {
    ignored_entries(0, p, stride).map_err(|e| e.error)?;
    if ok
        && let (Ok(fa), Ok(oa)) = (
            <&[f64; NF]>::try_from(f),
            <&mut [f64; ND]>::try_from(&mut *o),
        )
        && let Some(acc) =
            super::kernel::blend_cell::<ND, NF>(view.packed, n, view.y.nodes.len(), w, fa)
        && acc.iter().fold(0.0, |a, v| a + v * 0.0) == 0.0
    {
        *oa = acc;
        return Ok(Some(Placement::Inside));
    }
    let (Some(&px), Some(&py)) = (p.first(), p.get(1)) else {
        return Ok(None);
    };
    view.eval([px, py], f, o, options).map(Some)
}

/// [`finish_row`] for a row whose cell is not known yet (a batch's last rows, or a group of
/// the lane kernel it declined): the first phase's arithmetic for this one row.
#[cfg(all(feature = "std", target_arch = "x86_64"))]
#[inline(always)]
pub(super) fn one_row<const ND: usize, const NF: usize>(
    view: &ComplianceMapView<'_>,
    (ex, ey): (&EvenAxis<'_>, &EvenAxis<'_>),
    row: Row<'_>,
    options: QueryOptions,
) -> Result<Option<Placement>, TickError> {
    let (n, w, ok) = cell(ex, ey, view.y.nodes.len(), row.p, row.f);
    finish_row::<ND, NF>(view, (n, &w, ok), row, options)
}

/// Row `p`'s first node, bilinear weights (Eq. 14) and whether it is inside the grid with
/// finite input and no rounding correction needed: branch-free, the single query's
/// arithmetic (`cell_nodes`, `cell_t_inside`, `bilinear_stencil`).
#[inline(always)]
pub(super) fn cell(
    ex: &EvenAxis<'_>,
    ey: &EvenAxis<'_>,
    ny: usize,
    p: &[f64],
    f: &[f64],
) -> (usize, [f64; 4], bool) {
    let px = p.first().copied().unwrap_or(f64::NAN);
    let py = p.get(1).copied().unwrap_or(f64::NAN);
    // NaN and infinities make this NaN; finite values make it exactly 0.
    let probe = f.iter().fold(px * 0.0 + py * 0.0, |a, v| a + v * 0.0);
    let (i, tx, ok_x) = ex.cell_t(px);
    let (j, ty, ok_y) = ey.cell_t(py);
    let (ux, uy) = (1.0 - tx, 1.0 - ty);
    (
        i * ny + j,
        [ux * uy, ux * ty, tx * uy, tx * ty],
        (probe == 0.0) & ok_x & ok_y,
    )
}
