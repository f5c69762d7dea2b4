//! The displacement field of a compliance map under one fixed load: the node displacements
//! of Eq. 9-10 computed once, so a query only blends them (Eq. 14 or the cubic option).
//! For a process whose force does not change between queries, e.g. a constant milling load
//! swept over the workspace, or a map of the gravity sag.

use alloc::vec::Vec;

use super::{BatchError, BatchSummary, ComplianceMap, QueryOptions};
use crate::error::{BuildError, Placement, TickError};

/// A compliance map evaluated at one load (`alloc`): queries take a position only. Built by
/// [`ComplianceMap::field`]; gives the map's results under that load, to rounding of the
/// node sums (the same blend of the same node values).
#[derive(Debug, Clone, PartialEq)]
pub struct DisplacementField {
    /// One force axis with unit load: node values as slopes, zero offsets.
    values: ComplianceMap,
    force: Vec<f64>,
}

impl ComplianceMap {
    /// The displacement field under the fixed `force` (`n_force` entries, \[N\] or \[N m\],
    /// finite): every node's displacement (Eq. 9-10) computed once. O(nodes).
    pub fn field(&self, force: &[f64]) -> Result<DisplacementField, BuildError> {
        let (nf, nd) = (self.n_force(), self.n_displacement());
        if force.len() != nf {
            return Err(BuildError::WrongLength {
                what: "force",
                expected: nf,
                got: force.len(),
            });
        }
        if let Some(index) = force.iter().position(|f| !f.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "force",
                index,
            });
        }
        let nodes = self.x().len() * self.y().len();
        let view = self.view();
        let mut values: Vec<f64> = Vec::with_capacity(nodes * nd);
        for node in 0..nodes {
            let v = view.node_value_dyn(node, force);
            values.extend(v.iter().take(nd));
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "field (force too large for the map)",
                index,
            });
        }
        let zeros = alloc::vec![0.0; values.len()];
        let values =
            ComplianceMap::new(self.x().to_vec(), self.y().to_vec(), 1, nd, values, zeros)?
                .with_options(self.options());
        Ok(DisplacementField {
            values,
            force: force.to_vec(),
        })
    }
}

impl DisplacementField {
    /// Displacement \[m | rad\] at `position` `[x, y]` \[m\] into `out` (`n_displacement`
    /// entries) with the map's default options. Allocation-free, never panics.
    #[inline]
    pub fn displacement(
        &self,
        position: [f64; 2],
        out: &mut [f64],
    ) -> Result<Placement, TickError> {
        self.values.displacement(position, &[1.0], out)
    }

    /// [`Self::displacement`] with explicit options.
    #[inline]
    pub fn displacement_with(
        &self,
        position: [f64; 2],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<Placement, TickError> {
        self.values
            .displacement_with(position, &[1.0], out, options)
    }

    /// Many positions, allocation-free: row `r` reads `positions[r * stride..]` (x, y \[m\];
    /// further entries ignored, but refused when not finite) and writes `out[r * n_displacement..]`. Stops at the first
    /// refused row.
    pub fn displacement_batch(
        &self,
        positions: &[f64],
        stride: usize,
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<BatchSummary, BatchError> {
        let nd = self.n_displacement();
        let rows = out.len() / nd.max(1);
        if stride < 2 || positions.len() != rows * stride || out.len() != rows * nd {
            return Err(BatchError {
                row: 0,
                error: TickError::WrongLength {
                    what: "positions",
                    expected: rows * stride.max(2),
                    got: positions.len(),
                },
            });
        }
        let mut summary = BatchSummary::default();
        for (row, (p, o)) in positions
            .chunks_exact(stride)
            .zip(out.chunks_exact_mut(nd))
            .enumerate()
        {
            let (Some(&x), Some(&y)) = (p.first(), p.get(1)) else {
                continue;
            };
            if let Some(index) = super::ignored_non_finite(p) {
                let error = TickError::NonFinite {
                    what: "position",
                    index,
                };
                return Err(BatchError { row, error });
            }
            match self.values.displacement_with([x, y], &[1.0], o, options) {
                Ok(place) => summary.count(place),
                Err(error) => return Err(BatchError { row, error }),
            }
        }
        Ok(summary)
    }

    /// The load the field was computed for \[N | N m\].
    pub fn force(&self) -> &[f64] {
        &self.force
    }
    /// Number of displacement axes.
    pub fn n_displacement(&self) -> usize {
        self.values.n_displacement()
    }
    /// Node displacements (node `i * ny + j`, then axis) \[m | rad\].
    pub fn node_values(&self) -> &[f64] {
        self.values.slopes()
    }
    /// Node x coordinates \[m\].
    pub fn x(&self) -> &[f64] {
        self.values.x()
    }
    /// Node y coordinates \[m\].
    pub fn y(&self) -> &[f64] {
        self.values.y()
    }
    /// Default query options (the map's when built).
    pub fn options(&self) -> QueryOptions {
        self.values.options()
    }
}
