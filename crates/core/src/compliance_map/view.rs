//! The borrowed, allocation-free compliance map: what a real-time loop queries.

use super::{MAX_AXES, QueryOptions, grid};
use crate::error::BuildError;

/// Borrowed, allocation-free compliance map: the real-time lookup.
///
/// Coefficient layout (both `slopes` and `offsets`): node-major with `node = i * ny + j`
/// (`i` along x, `j` along y), then displacement axis `d`, then force axis `f`:
/// `index = (node * n_displacement + d) * n_force + f`.
#[derive(Debug, Clone, Copy)]
pub struct ComplianceMapView<'a> {
    pub(super) x: grid::Axis<'a>,
    pub(super) y: grid::Axis<'a>,
    pub(super) n_force: usize,
    pub(super) n_disp: usize,
    pub(super) slopes: &'a [f64],
    pub(super) offsets: &'a [f64],
    /// The coefficients again, node by node in the packed layout of the kernels (slopes,
    /// then offset sums), when the owner built them; empty for a view over plain tables,
    /// which sums the offsets per query instead (same results, bit for bit).
    pub(super) packed: &'a [f64],
    pub(super) options: QueryOptions,
}

pub(super) fn check_counts(n_force: usize, n_disp: usize) -> Result<(), BuildError> {
    for (what, count) in [("n_force", n_force), ("n_displacement", n_disp)] {
        if count == 0 || count > MAX_AXES {
            return Err(BuildError::InvalidParameter {
                what,
                value: count as f64,
                expected: "in 1..=6",
            });
        }
    }
    Ok(())
}

fn check_coefficients(
    nodes: usize,
    n_force: usize,
    n_disp: usize,
    slopes: &[f64],
    offsets: &[f64],
) -> Result<(), BuildError> {
    let expected = nodes * n_force * n_disp;
    for (what, v) in [("slopes", slopes), ("offsets", offsets)] {
        if v.len() != expected {
            return Err(BuildError::WrongLength {
                what,
                expected,
                got: v.len(),
            });
        }
        if let Some(index) = v.iter().position(|c| !c.is_finite()) {
            return Err(BuildError::NonFinite { what, index });
        }
    }
    Ok(())
}

impl<'a> ComplianceMapView<'a> {
    /// Checks and wraps borrowed tables: `x` (nx), `y` (ny) node coordinates \[m\], strictly
    /// increasing; `slopes` and `offsets` of length `nx * ny * n_displacement * n_force` in
    /// the layout of the type's documentation. O(nx + ny + coefficients), no allocation.
    pub fn new(
        x: &'a [f64],
        y: &'a [f64],
        n_force: usize,
        n_displacement: usize,
        slopes: &'a [f64],
        offsets: &'a [f64],
    ) -> Result<Self, BuildError> {
        check_counts(n_force, n_displacement)?;
        let xi = grid::check_axis(grid::AxisId::X, x)?;
        let yi = grid::check_axis(grid::AxisId::Y, y)?;
        check_coefficients(x.len() * y.len(), n_force, n_displacement, slopes, offsets)?;
        Ok(Self {
            x: grid::Axis {
                nodes: x,
                inv_step: xi,
            },
            y: grid::Axis {
                nodes: y,
                inv_step: yi,
            },
            n_force,
            n_disp: n_displacement,
            slopes,
            offsets,
            packed: &[],
            options: QueryOptions::default(),
        })
    }

    /// The same view with other default query options.
    #[must_use]
    pub fn with_options(mut self, options: QueryOptions) -> Self {
        self.options = options;
        self
    }

    /// Default query options.
    pub fn options(&self) -> QueryOptions {
        self.options
    }
    /// Number of force axes.
    pub fn n_force(&self) -> usize {
        self.n_force
    }
    /// Number of displacement axes.
    pub fn n_displacement(&self) -> usize {
        self.n_disp
    }
    /// Node x coordinates \[m\].
    pub fn x(&self) -> &'a [f64] {
        self.x.nodes
    }
    /// Node y coordinates \[m\].
    pub fn y(&self) -> &'a [f64] {
        self.y.nodes
    }
}
