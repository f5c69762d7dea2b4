//! Compliance map from static tests: the experimental compliance model of Paksoy, Dede and
//! Kiper (2025), "Enhancing trajectory-tracking accuracy of high-acceleration parallel robots
//! by predicting compliant displacements", sections 3.1-3.2, 4.2-4.3 and Appendix A.
//!
//! At each node `(x_i, y_j)` of a rectilinear grid of end-effector positions, every
//! displacement axis `d` responds to every force axis `f` along a line (Eq. 10):
//!
//! ```text
//! disp_d(x_i, y_j, F) = sum_f ( slope[d][f] * F_f + offset[d][f] )          (Eq. 9-10)
//! ```
//!
//! The lines are fitted by least squares from forces applied step by step (Eq. 11-13, see
//! [`fit()`]), and between nodes the node displacements are blended bilinearly from the 4
//! neighbouring nodes (Eq. 14) or, beyond the paper, with a C1 cubic Hermite interpolation
//! ([`Interpolation::Bicubic`]).
//!
//! * Units: SI inside. Positions \[m\]; forces \[N\] (moments \[N m\] if force axes 3..5 are
//!   used); displacements \[m\] (rotations \[rad\]); slopes \[m/N\] (or \[rad/N\], \[m/(N m)\], ...);
//!   offsets \[m\] (or \[rad\]). Loaders take the file units as explicit parameters.
//! * Dimensions: `n_force` force axes and `n_displacement` displacement axes, each 1..=6,
//!   chosen at run time ([`MAX_AXES`]); the paper's case is 2 x 2 (`Fx, Fy -> dx, dy`).
//! * Grid: `nx x ny >= 2 x 2`, strictly increasing coordinates, uneven spacing allowed. Cell
//!   lookup is O(1) on evenly spaced axes and a binary search otherwise.
//! * Per query ([`ComplianceMapView::displacement`], or [`step`] in the crate's tick shape
//!   with a [`Data`]): no allocation, no panic, a [`crate::Placement`] or a
//!   [`crate::TickError`]. Out-of-grid positions follow [`OutOfGrid`].
//!
//! The lookup lives in the borrowed, allocation-free [`ComplianceMapView`], usable without
//! `alloc` over `static` tables; the owning [`ComplianceMap`] and fitting (`alloc`) build on
//! it, and the CSV/JSON loaders live in [`crate::io`] (`std`).
//!
//! ```
//! use deflect_core::compliance_map::{self, ComplianceMap, Data};
//! // A 2 x 2 grid, one force axis, one displacement axis: 1 um/N everywhere, no offset.
//! let map = ComplianceMap::new(
//!     vec![0.0, 0.1], vec![0.0, 0.1], 1, 1, vec![1e-6; 4], vec![0.0; 4])?;
//! let view = map.view();
//! let mut data = Data::new(&view);
//! compliance_map::step(&view, &mut data, [0.05, 0.02], &[200.0]).unwrap();
//! assert!((data.displacement()[0] - 2e-4).abs() < 1e-15);
//! # Ok::<(), deflect_core::BuildError>(())
//! ```

mod batch;
#[cfg(all(feature = "std", target_arch = "x86_64"))]
mod batch_avx2;
mod batch_row;
mod grid;
mod interp;
mod kernel;
mod view;

#[cfg(feature = "alloc")]
mod cross_validation;
#[cfg(feature = "alloc")]
mod field;
#[cfg(feature = "alloc")]
mod fit;
#[cfg(feature = "alloc")]
mod fit_stats;
#[cfg(feature = "alloc")]
mod map;
#[cfg(feature = "alloc")]
mod nd;
#[cfg(feature = "alloc")]
mod nd_fit;

#[cfg(feature = "alloc")]
pub use cross_validation::{CrossValidation, HeldOutNode, HoldOutAxis, leave_one_node_out};
#[cfg(feature = "alloc")]
pub use field::DisplacementField;
#[cfg(feature = "std")]
pub(crate) use fit::grid_of;
#[cfg(feature = "alloc")]
pub use fit::{FitOptions, Measurement, fit, two_point_displacement};
#[cfg(feature = "alloc")]
pub use fit_stats::{LineStats, NodeFit};
pub use interp::{BatchError, BatchSummary};
#[cfg(feature = "alloc")]
pub use map::ComplianceMap;
#[cfg(feature = "alloc")]
pub use nd::{GridMap, MAX_GRID_DIMS, MAX_GRID_NODES};
#[cfg(feature = "alloc")]
pub use nd_fit::{GridMeasurement, fit_grid};
pub use view::ComplianceMapView;

use crate::error::{Placement, TickError};

/// Most force axes and most displacement axes a map holds (a 6-D wrench and a 6-D twist).
pub const MAX_AXES: usize = 6;

/// Most measurements one [`fit`] takes, and most force rows one [`leave_one_node_out`]
/// evaluates: 100 000, the one budget of measurements in deflect (the identification's
/// too), far above a static test campaign (the paper's maps take 245 rows).
pub const MAX_MEASUREMENTS: usize = 100_000;

/// How node values are blended between nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "std",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum Interpolation {
    /// Eq. 14: bilinear between the 4 nodes of the cell (C0).
    #[default]
    Bilinear,
    /// Tensor-product cubic Hermite (C1): node slopes from the three-point finite difference
    /// that is exact for quadratics on uneven spacing (one-sided at the grid ends; linear
    /// along an axis with 2 nodes). Uses up to 4 x 4 nodes. Equals Catmull-Rom on even grids
    /// away from the ends.
    Bicubic,
}

/// What to do with a position outside the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "std",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum OutOfGrid {
    /// Refuse with [`crate::TickError::OutOfGrid`].
    #[default]
    Error,
    /// Move the position to the nearest grid boundary and report [`crate::Placement::Clamped`].
    Clamp,
    /// Continue linearly from the boundary cell (bilinear: the cell's own formula; bicubic:
    /// the boundary node's value and slope) and report [`crate::Placement::Extrapolated`].
    Extrapolate,
}

/// Options of one query.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "std", derive(serde::Serialize, serde::Deserialize))]
pub struct QueryOptions {
    /// Interpolation between nodes.
    pub interpolation: Interpolation,
    /// Policy outside the grid.
    pub out_of_grid: OutOfGrid,
}

/// Per-query workspace of the tick shape: the displacement of the last [`step`] (or
/// [`step_grid`]) and the axis counts of the map it was made for. Queries need no other buffer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Data {
    n_force: usize,
    n_disp: usize,
    /// Displacement of the last query \[m | rad\]; entries past `n_displacement` are zero.
    pub displacement: [f64; MAX_AXES],
    /// Where the last query fell.
    pub placement: Placement,
}

/// What a [`Data`] workspace is sized by: a map's force and displacement axis counts. The
/// 2-D map and the N-D [`GridMap`] both have them, so one workspace and one tick shape serve
/// both ([`step`] and [`step_grid`]).
pub trait MapAxes {
    /// Force axes the map is loaded along (`F` of `[F, D]` coefficients).
    fn force_axes(&self) -> usize;
    /// Displacement axes the map returns.
    fn displacement_axes(&self) -> usize;
}

impl MapAxes for ComplianceMapView<'_> {
    fn force_axes(&self) -> usize {
        self.n_force()
    }
    fn displacement_axes(&self) -> usize {
        self.n_displacement()
    }
}

#[cfg(feature = "alloc")]
impl MapAxes for ComplianceMap {
    fn force_axes(&self) -> usize {
        self.n_force()
    }
    fn displacement_axes(&self) -> usize {
        self.n_displacement()
    }
}

#[cfg(feature = "alloc")]
impl MapAxes for GridMap {
    fn force_axes(&self) -> usize {
        self.n_force()
    }
    fn displacement_axes(&self) -> usize {
        self.n_displacement()
    }
}

impl Data {
    /// A workspace for `map` (a 2-D view or map, or an N-D grid map).
    pub fn new<M: MapAxes + ?Sized>(map: &M) -> Self {
        Self {
            n_force: map.force_axes(),
            n_disp: map.displacement_axes(),
            displacement: [0.0; MAX_AXES],
            placement: Placement::Inside,
        }
    }

    /// Whether this workspace was made for a map of `map`'s dimensions.
    pub fn check<M: MapAxes + ?Sized>(&self, map: &M) -> bool {
        self.n_force == map.force_axes() && self.n_disp == map.displacement_axes()
    }

    /// The displacement of the last query, `n_displacement` entries.
    pub fn displacement(&self) -> &[f64] {
        self.displacement.get(..self.n_disp).unwrap_or(&[])
    }

    /// Runs `query` into this workspace's displacement after checking it was made for `map`:
    /// the part [`step`] and [`step_grid`] share.
    #[inline(always)]
    fn query<M: MapAxes + ?Sized>(
        &mut self,
        map: &M,
        query: impl FnOnce(&mut [f64]) -> Result<Placement, TickError>,
    ) -> Result<Placement, TickError> {
        if !self.check(map) {
            return Err(TickError::ModelMismatch {
                what: "map axes",
                expected: map.force_axes() * MAX_AXES + map.displacement_axes(),
                got: self.n_force * MAX_AXES + self.n_disp,
            });
        }
        let out = self.displacement.get_mut(..self.n_disp).unwrap_or(&mut []);
        let placement = query(out)?;
        self.placement = placement;
        Ok(placement)
    }
}

/// The immutable model of the tick shape: a borrowed compliance map (an owning
/// [`ComplianceMap`] lends one with `view()`); [`Data`] holds the last query and [`step`]
/// queries.
pub type Model<'a> = ComplianceMapView<'a>;

/// `[x, y]` of a query position given as 2 or 3 entries \[m\]: the maps are planar, so a z
/// entry is ignored, but it must be finite like the others (a NaN anywhere in a position is
/// a broken input, not a value to drop).
pub fn planar_position(p: &[f64]) -> Result<[f64; 2], TickError> {
    match *p {
        [x, y] | [x, y, _] => {
            crate::error::check_finite("position", p)?;
            Ok([x, y])
        }
        _ => Err(TickError::WrongLength {
            what: "position (x, y or x, y, z)",
            expected: 2,
            got: p.len(),
        }),
    }
}

/// The entries of a batch row past x and y (z, ignored) must be finite too: the index of the
/// first that is not, counted in the row.
#[inline(always)]
pub(crate) fn ignored_non_finite(row: &[f64]) -> Option<usize> {
    row.iter()
        .skip(2)
        .position(|v| !v.is_finite())
        .map(|k| k + 2)
}

/// One query of the tick shape: the displacement at `position` `[x, y]` \[m\] under `force`
/// (`n_force` entries \[N | N m\]) with the map's default options, into `data.displacement`.
/// Allocation-free, never panics; see [`ComplianceMapView::displacement_with`].
#[inline]
pub fn step(
    map: &Model<'_>,
    data: &mut Data,
    position: [f64; 2],
    force: &[f64],
) -> Result<Placement, TickError> {
    data.query(map, |out| map.displacement(position, force, out))
}

/// One query of the tick shape on an N-D grid map: the displacement at `point` (one
/// coordinate per grid axis, in the axes' units) under `force` (`n_force` entries
/// \[N | N m\]) with the map's default options, into `data.displacement`. Allocation-free,
/// never panics; see [`GridMap::displacement_with`]. A 2-D `GridMap::from_map(&map)` gives
/// what [`step`] gives on `map`, bit for bit (the 2-D map is the grid map's fast path).
#[cfg(feature = "alloc")]
#[inline]
pub fn step_grid(
    map: &GridMap,
    data: &mut Data,
    point: &[f64],
    force: &[f64],
) -> Result<Placement, TickError> {
    data.query(map, |out| map.displacement(point, force, out))
}

/// Square root usable without `std`.
#[cfg(feature = "alloc")]
#[inline]
fn sqrt(v: f64) -> f64 {
    nalgebra::ComplexField::sqrt(v)
}
