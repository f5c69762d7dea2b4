//! Evaluation of the map: the node lines (Eq. 9-10) combined with the 2-D weights of Eq. 14
//! (bilinear) or of the cubic Hermite option.

use super::{ComplianceMapView, Interpolation, QueryOptions};
use crate::error::{Placement, TickError};

/// Row `row`'s entries past x and y (z, ignored) must be finite: the batch's error otherwise.
#[inline(always)]
pub(super) fn ignored_entries(row: usize, p: &[f64], stride: usize) -> Result<(), BatchError> {
    if stride <= 2 {
        return Ok(());
    }
    match super::ignored_non_finite(p) {
        Some(index) => Err(BatchError {
            row,
            error: TickError::NonFinite {
                what: "position",
                index,
            },
        }),
        None => Ok(()),
    }
}

impl ComplianceMapView<'_> {
    /// Displacement at `position` `[x, y]` \[m\] under `force` (`n_force` entries, \[N\] or
    /// \[N m\]) written into `out` (`n_displacement` entries, \[m\] or \[rad\]), with explicit
    /// query options. Allocation-free, never panics.
    ///
    /// At a node this is Eq. 9-10: `out[d] = sum_f (slope[d][f] * force[f] + offset[d][f])`.
    /// Between nodes the node values are blended with the weights of Eq. 14 (bilinear) or of
    /// the cubic Hermite interpolation; both are linear in the node values, so the blend is
    /// done once on the coefficients.
    #[inline]
    pub fn displacement_with(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<Placement, TickError> {
        self.eval(position, force, out, options)
    }

    /// Many queries in one call, allocation-free: row `r` reads `positions[r * stride..]`
    /// (x, y \[m\]; entries past the first two, e.g. z, are ignored), `forces[r * n_force..]`
    /// \[N\] and writes `out[r * n_displacement..]` \[m\]. Stops at the first refused row.
    pub fn displacement_batch(
        &self,
        positions: &[f64],
        stride: usize,
        forces: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<BatchSummary, BatchError> {
        let (nf, nd) = (self.n_force, self.n_disp);
        let rows = forces.len() / nf;
        let shape_err = |what, expected, got| BatchError {
            row: 0,
            error: TickError::WrongLength {
                what,
                expected,
                got,
            },
        };
        if forces.len() != rows * nf {
            return Err(shape_err("forces", rows * nf, forces.len()));
        }
        if stride < 2 || positions.len() != rows * stride {
            return Err(shape_err(
                "positions",
                rows * stride.max(2),
                positions.len(),
            ));
        }
        if out.len() != rows * nd {
            return Err(shape_err("out", rows * nd, out.len()));
        }
        if options.interpolation == Interpolation::Bilinear {
            macro_rules! fixed {
                ($nd:literal, $nf:literal) => {
                    return self.batch_bilinear::<$nd, $nf>(positions, stride, forces, out, options)
                };
            }
            match (nd, nf) {
                (2, 2) => fixed!(2, 2),
                (3, 3) => fixed!(3, 3),
                (6, 6) => fixed!(6, 6),
                _ => {}
            }
        }
        let mut summary = BatchSummary::default();
        for (row, ((p, f), o)) in positions
            .chunks_exact(stride)
            .zip(forces.chunks_exact(nf))
            .zip(out.chunks_exact_mut(nd))
            .enumerate()
        {
            let (Some(&x), Some(&y)) = (p.first(), p.get(1)) else {
                continue;
            };
            ignored_entries(row, p, stride)?;
            match self.eval([x, y], f, o, options) {
                Ok(place) => summary.count(place),
                Err(error) => return Err(BatchError { row, error }),
            }
        }
        Ok(summary)
    }

    /// Bilinear batch with the sizes fixed: rows inside the grid with finite input take the
    /// fixed kernel, the others [`Self::eval`] for their exact status or error; both give the
    /// bits of a single query.
    fn batch_bilinear<const ND: usize, const NF: usize>(
        &self,
        positions: &[f64],
        stride: usize,
        forces: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<BatchSummary, BatchError> {
        if let Some(result) =
            self.batch_bilinear_even::<ND, NF>(positions, stride, forces, out, options)
        {
            return result;
        }
        let mut summary = BatchSummary::default();
        for (row, ((p, f), o)) in positions
            .chunks_exact(stride)
            .zip(forces.chunks_exact(NF))
            .zip(out.chunks_exact_mut(ND))
            .enumerate()
        {
            let (Some(&px), Some(&py), Ok(fa), Ok(oa)) = (
                p.first(),
                p.get(1),
                <&[f64; NF]>::try_from(f),
                <&mut [f64; ND]>::try_from(&mut *o),
            ) else {
                continue;
            };
            ignored_entries(row, p, stride)?;
            match self.bilinear_inside::<ND, NF>([px, py], fa) {
                Some(acc) if acc.iter().fold(0.0, |a, v| a + v * 0.0) == 0.0 => {
                    *oa = acc;
                    summary.inside += 1;
                }
                _ => match self.eval([px, py], f, o, options) {
                    Ok(place) => summary.count(place),
                    Err(error) => return Err(BatchError { row, error }),
                },
            }
        }
        Ok(summary)
    }

    #[inline(always)]
    pub(super) fn eval(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<Placement, TickError> {
        if options.interpolation == Interpolation::Bilinear {
            macro_rules! fixed {
                ($nd:literal, $nf:literal) => {
                    if let (Ok(f), Ok(o)) = (
                        <&[f64; $nf]>::try_from(force),
                        <&mut [f64; $nd]>::try_from(&mut *out),
                    ) {
                        if let Some(acc) = self.bilinear_inside::<$nd, $nf>(position, f) {
                            *o = acc;
                            crate::error::check_output("displacement", o)?;
                            return Ok(Placement::Inside);
                        }
                    }
                };
            }
            match (self.n_disp, self.n_force) {
                (2, 2) => fixed!(2, 2),
                (3, 3) => fixed!(3, 3),
                (6, 6) => fixed!(6, 6),
                _ => {}
            }
        }
        self.eval_general(position, force, out, options)
    }

    /// Any query: checks, out-of-grid policy, bilinear or cubic weights.
    fn eval_general(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<Placement, TickError> {
        let (nf, nd) = (self.n_force, self.n_disp);
        if force.len() != nf {
            return Err(TickError::WrongLength {
                what: "force",
                expected: nf,
                got: force.len(),
            });
        }
        if out.len() != nd {
            return Err(TickError::WrongLength {
                what: "out",
                expected: nd,
                got: out.len(),
            });
        }
        if let Some(index) = position.iter().position(|v| !v.is_finite()) {
            return Err(TickError::NonFinite {
                what: "position",
                index,
            });
        }
        if let Some(index) = force.iter().position(|v| !v.is_finite()) {
            return Err(TickError::NonFinite {
                what: "force",
                index,
            });
        }
        let [px, py] = position;
        let policy = options.out_of_grid;
        let ny = self.y.nodes.len();
        // (node, weight) pairs: 4 for Eq. 14, up to 16 for the cubic option.
        let (plx, ply) = if options.interpolation == Interpolation::Bilinear {
            let (i, tx, plx) = self.x.cell_t(0, px, policy)?;
            let (j, ty, ply) = self.y.cell_t(1, py, policy)?;
            let (nodes, weights) = self.bilinear_stencil(i, j, tx, ty);
            self.blend(&nodes, &weights, force, out);
            (plx, ply)
        } else {
            let (sx, plx) = self.x.stencil(0, px, options.interpolation, policy)?;
            let (sy, ply) = self.y.stencil(1, py, options.interpolation, policy)?;
            let mut nodes = [0usize; 16];
            let mut weights = [0.0f64; 16];
            let mut count = 0;
            for (a, wa) in sx.w.iter().take(sx.len).enumerate() {
                for (b, wb) in sy.w.iter().take(sy.len).enumerate() {
                    let w = wa * wb;
                    if w != 0.0
                        && let (Some(n), Some(ws)) = (nodes.get_mut(count), weights.get_mut(count))
                    {
                        *n = (sx.base + a) * ny + sy.base + b;
                        *ws = w;
                        count += 1;
                    }
                }
            }
            self.blend(
                nodes.get(..count).unwrap_or(&[]),
                weights.get(..count).unwrap_or(&[]),
                force,
                out,
            );
            (plx, ply)
        };
        // Extrapolating far out (or forces near f64::MAX) overflows: refuse, never NaN.
        crate::error::check_output("displacement", out)?;
        // A clamped axis wins over an extrapolated one: the position actually evaluated
        // was moved.
        Ok(match (plx, ply) {
            (Placement::Inside, Placement::Inside) => Placement::Inside,
            (Placement::Clamped, _) | (_, Placement::Clamped) => Placement::Clamped,
            _ => Placement::Extrapolated,
        })
    }

    /// [`Self::displacement_with`] with the view's default options.
    #[inline]
    pub fn displacement(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
    ) -> Result<Placement, TickError> {
        self.displacement_with(position, force, out, self.options)
    }
}

/// Rows per placement of a successful [`ComplianceMapView::displacement_batch`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BatchSummary {
    /// Rows inside the grid.
    pub inside: usize,
    /// Rows clamped to the boundary.
    pub clamped: usize,
    /// Rows extrapolated.
    pub extrapolated: usize,
}

impl BatchSummary {
    /// Counts one row's placement.
    #[inline(always)]
    pub(super) fn count(&mut self, place: Placement) {
        match place {
            Placement::Inside => self.inside += 1,
            Placement::Clamped => self.clamped += 1,
            Placement::Extrapolated => self.extrapolated += 1,
        }
    }
}

/// The first row a batch refused and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatchError {
    /// Row index (0 for a shape error).
    pub row: usize,
    /// The reason.
    pub error: TickError,
}

impl core::fmt::Display for BatchError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "row {}: {}", self.row, self.error)
    }
}

impl core::error::Error for BatchError {}
