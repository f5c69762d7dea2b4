//! Evaluation of the map: the node lines (Eq. 9-10) combined with the 2-D weights of Eq. 14
//! (bilinear) or of the cubic Hermite option.

use super::{ComplianceMapView, Interpolation, QueryOptions};
use crate::error::{Placement, TickError};

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
        if options.interpolation == Interpolation::Bilinear && (nd, nf) == (2, 2) {
            return self.batch_bilinear_2x2(positions, stride, forces, out, options);
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
            match self.eval([x, y], f, o, options) {
                Ok(Placement::Inside) => summary.inside += 1,
                Ok(Placement::Clamped) => summary.clamped += 1,
                Ok(Placement::Extrapolated) => summary.extrapolated += 1,
                Err(error) => return Err(BatchError { row, error }),
            }
        }
        Ok(summary)
    }

    /// Bilinear batch kernel of the paper's 2-force, 2-displacement case: the same arithmetic
    /// as [`Self::eval`] (same results bit for bit), with the per-row checks reduced to one
    /// finiteness test and one range test; rows failing either go through [`Self::eval`] for
    /// the exact status or error.
    fn batch_bilinear_2x2(
        &self,
        positions: &[f64],
        stride: usize,
        forces: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<BatchSummary, BatchError> {
        let ny = self.y.nodes.len();
        let (x_lo, x_hi) = (self.x.first(), self.x.last());
        let (y_lo, y_hi) = (self.y.first(), self.y.last());
        // Nodes (i, j) and (i, j + 1) are adjacent in memory: one slice for both.
        let pair = |k: usize| -> Option<(&[f64; 8], &[f64; 8])> {
            let r = k * 4..k * 4 + 8;
            let s = self.slopes.get(r.clone())?.try_into().ok()?;
            let o = self.offsets.get(r)?.try_into().ok()?;
            Some((s, o))
        };
        let mut summary = BatchSummary::default();
        for (row, ((p, f), o)) in positions
            .chunks_exact(stride)
            .zip(forces.chunks_exact(2))
            .zip(out.chunks_exact_mut(2))
            .enumerate()
        {
            let (Some(&px), Some(&py), Ok(&[f0, f1]), Ok(o)) = (
                p.first(),
                p.get(1),
                <&[f64; 2]>::try_from(f),
                <&mut [f64; 2]>::try_from(o),
            ) else {
                continue;
            };
            // NaN and infinities make this NaN; finite values make it exactly 0.
            let probe = px * 0.0 + py * 0.0 + f0 * 0.0 + f1 * 0.0;
            let inside = px >= x_lo && px <= x_hi && py >= y_lo && py <= y_hi;
            if probe != 0.0 || !inside {
                match self.eval([px, py], f, o, options) {
                    Ok(Placement::Inside) => summary.inside += 1,
                    Ok(Placement::Clamped) => summary.clamped += 1,
                    Ok(Placement::Extrapolated) => summary.extrapolated += 1,
                    Err(error) => return Err(BatchError { row, error }),
                }
                continue;
            }
            let (i, tx) = self.x.cell_t_inside(px);
            let (j, ty) = self.y.cell_t_inside(py);
            let n00 = i * ny + j;
            let (ux, uy) = (1.0 - tx, 1.0 - ty);
            let (Some((s0, c0)), Some((s1, c1))) = (pair(n00), pair(n00 + ny)) else {
                continue; // unreachable for a validated view
            };
            let w = [ux * uy, ux * ty, tx * uy, tx * ty];
            // Same operations in the same order as `blend` (bit-identical results).
            let mut acc = [0.0; 2];
            for (d, acc_d) in acc.iter_mut().enumerate() {
                let (a, b) = (2 * d, 2 * d + 1);
                let (Some(sa0), Some(sb0), Some(ca0), Some(cb0)) =
                    (s0.get(a), s0.get(b), c0.get(a), c0.get(b))
                else {
                    continue;
                };
                let (Some(sa1), Some(sb1), Some(ca1), Some(cb1)) =
                    (s0.get(a + 4), s0.get(b + 4), c0.get(a + 4), c0.get(b + 4))
                else {
                    continue;
                };
                let (Some(sa2), Some(sb2), Some(ca2), Some(cb2)) =
                    (s1.get(a), s1.get(b), c1.get(a), c1.get(b))
                else {
                    continue;
                };
                let (Some(sa3), Some(sb3), Some(ca3), Some(cb3)) =
                    (s1.get(a + 4), s1.get(b + 4), c1.get(a + 4), c1.get(b + 4))
                else {
                    continue;
                };
                *acc_d += w[0] * ((sa0 * f0 + ca0) + (sb0 * f1 + cb0));
                *acc_d += w[1] * ((sa1 * f0 + ca1) + (sb1 * f1 + cb1));
                *acc_d += w[2] * ((sa2 * f0 + ca2) + (sb2 * f1 + cb2));
                *acc_d += w[3] * ((sa3 * f0 + ca3) + (sb3 * f1 + cb3));
            }
            if !(acc[0].is_finite() && acc[1].is_finite()) {
                let index = usize::from(acc[0].is_finite());
                return Err(BatchError {
                    row,
                    error: TickError::NonFiniteOutput {
                        what: "displacement",
                        index,
                    },
                });
            }
            *o = acc;
            summary.inside += 1;
        }
        Ok(summary)
    }

    #[inline(always)]
    fn eval(
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
            // Eq. 14: weights (x2 - x)(y2 - y), (x2 - x)(y - y1), ... / ((x2 - x1)(y2 - y1)).
            let (i, tx, plx) = self.x.cell_t(0, px, policy)?;
            let (j, ty, ply) = self.y.cell_t(1, py, policy)?;
            let n00 = i * ny + j;
            let nodes = [n00, n00 + 1, n00 + ny, n00 + ny + 1];
            let (ux, uy) = (1.0 - tx, 1.0 - ty);
            let weights = [ux * uy, ux * ty, tx * uy, tx * ty];
            self.dispatch(&nodes, &weights, force, out);
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
                    if w != 0.0 {
                        if let (Some(n), Some(ws)) = (nodes.get_mut(count), weights.get_mut(count))
                        {
                            *n = (sx.base + a) * ny + sy.base + b;
                            *ws = w;
                            count += 1;
                        }
                    }
                }
            }
            self.dispatch(
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

    /// Fixed-size kernels for the common shapes (the paper's 2 x 2, 3-D, 6-D), a generic one
    /// otherwise; all produce the same sums in the same order.
    #[inline(always)]
    fn dispatch(&self, nodes: &[usize], weights: &[f64], force: &[f64], out: &mut [f64]) {
        match (self.n_disp, self.n_force) {
            (2, 2) => self.blend::<2, 2>(nodes, weights, force, out),
            (3, 3) => self.blend::<3, 3>(nodes, weights, force, out),
            (6, 6) => self.blend::<6, 6>(nodes, weights, force, out),
            _ => self.blend_dyn(nodes, weights, force, out),
        }
    }

    /// `out = sum_n w_n * sum_f (slope_n[d][f] * force[f] + offset_n[d][f])`, sizes fixed.
    #[inline(always)]
    fn blend<const ND: usize, const NF: usize>(
        &self,
        nodes: &[usize],
        weights: &[f64],
        force: &[f64],
        out: &mut [f64],
    ) {
        let block = ND * NF;
        let mut f = [0.0; NF];
        f.iter_mut().zip(force).for_each(|(a, b)| *a = *b);
        let mut acc = [0.0; ND];
        for (node, w) in nodes.iter().zip(weights) {
            let start = node * block;
            let (Some(s), Some(o)) = (
                self.slopes.get(start..start + block),
                self.offsets.get(start..start + block),
            ) else {
                continue; // unreachable for a validated view
            };
            for ((acc_d, s_row), o_row) in acc
                .iter_mut()
                .zip(s.chunks_exact(NF))
                .zip(o.chunks_exact(NF))
            {
                let (Ok(s_row), Ok(o_row)) =
                    (<&[f64; NF]>::try_from(s_row), <&[f64; NF]>::try_from(o_row))
                else {
                    continue;
                };
                let mut v = 0.0;
                for ((sk, ok), fk) in s_row.iter().zip(o_row).zip(&f) {
                    v += sk * fk + ok;
                }
                *acc_d += w * v;
            }
        }
        out.iter_mut().zip(acc.iter()).for_each(|(o, a)| *o = *a);
    }

    /// Generic-size version of [`Self::blend`].
    fn blend_dyn(&self, nodes: &[usize], weights: &[f64], force: &[f64], out: &mut [f64]) {
        let (nd, nf) = (self.n_disp, self.n_force);
        let block = nd * nf;
        out.iter_mut().for_each(|o| *o = 0.0);
        for (node, w) in nodes.iter().zip(weights) {
            let start = node * block;
            let (Some(slopes), Some(offsets)) = (
                self.slopes.get(start..start + block),
                self.offsets.get(start..start + block),
            ) else {
                continue; // unreachable for a validated view
            };
            for ((o, s_row), o_row) in out
                .iter_mut()
                .zip(slopes.chunks_exact(nf))
                .zip(offsets.chunks_exact(nf))
            {
                let mut v = 0.0;
                for ((s, c), f) in s_row.iter().zip(o_row.iter()).zip(force.iter()) {
                    v += s * f + c;
                }
                *o += w * v;
            }
        }
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
