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
//! * Units: SI inside. Positions [m]; forces [N] (moments [N m] if force axes 3..5 are
//!   used); displacements [m] (rotations [rad]); slopes [m/N] (or [rad/N], [m/(N m)], ...);
//!   offsets [m] (or [rad]). Loaders take the file units as explicit parameters.
//! * Dimensions: `n_force` force axes and `n_displacement` displacement axes, each 1..=6,
//!   chosen at run time ([`MAX_AXES`]); the paper's case is 2 x 2 (`Fx, Fy -> dx, dy`).
//! * Grid: `nx x ny >= 2 x 2`, strictly increasing coordinates, uneven spacing allowed. Cell
//!   lookup is O(1) on evenly spaced axes and a binary search otherwise.
//! * Per query ([`ComplianceMapView::displacement`]): no allocation, no panic, a
//!   [`QueryStatus`] or a [`QueryError`]. Out-of-grid positions follow [`OutOfGrid`].
//!
//! The lookup lives in the borrowed, allocation-free [`ComplianceMapView`], usable without
//! `alloc` over `static` tables; the owning [`ComplianceMap`], fitting, loaders (`alloc`) and
//! JSON/CSV (`std`) build on it.

// Units are written in brackets ("[m]", "[N]") as elsewhere in the crate; they are not links.
#![allow(rustdoc::broken_intra_doc_links)]

mod grid;
mod interp;

#[cfg(feature = "alloc")]
mod fit;
#[cfg(feature = "std")]
mod io;

use core::fmt;

#[cfg(feature = "alloc")]
use alloc::{string::String, vec::Vec};

#[cfg(feature = "alloc")]
pub use fit::{FitOptions, LineStats, Measurement, NodeFit, fit, two_point_displacement};
pub use interp::{BatchError, BatchSummary};
#[cfg(feature = "alloc")]
pub use interp::{CrossValidation, HeldOutNode, HoldOutAxis, leave_one_node_out};
#[cfg(feature = "std")]
pub use io::JSON_FORMAT_VERSION;

/// Most force axes and most displacement axes a map holds (a 6-D wrench and a 6-D twist).
pub const MAX_AXES: usize = 6;

/// Standard gravity [m/s^2]: 1 kgf = 9.80665 N.
pub const STANDARD_GRAVITY: f64 = 9.80665;

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
    /// Refuse with [`QueryError::OutOfGrid`].
    #[default]
    Error,
    /// Move the position to the nearest grid boundary and report [`QueryStatus::Clamped`].
    Clamp,
    /// Continue linearly from the boundary cell (bilinear: the cell's own formula; bicubic:
    /// the boundary node's value and slope) and report [`QueryStatus::Extrapolated`].
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

/// Where a successful query fell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QueryStatus {
    /// Inside the grid (boundary included).
    Inside,
    /// Outside along at least one axis and clamped to the boundary.
    Clamped,
    /// Outside along at least one axis and extrapolated.
    Extrapolated,
}

/// Why a query was refused. `Copy`, cheap, never a panic.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum QueryError {
    /// A slice has the wrong length.
    WrongLength {
        /// "force" or "out".
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length received.
        got: usize,
    },
    /// NaN or an infinity in the input.
    NonFinite {
        /// "position" or "force".
        what: &'static str,
        /// Index of the first non-finite entry.
        index: usize,
    },
    /// The position is outside the grid and the policy is [`OutOfGrid::Error`].
    OutOfGrid {
        /// 0 for x, 1 for y.
        axis: usize,
        /// The coordinate [m].
        value: f64,
        /// Lowest node coordinate [m].
        min: f64,
        /// Highest node coordinate [m].
        max: f64,
    },
}

impl fmt::Display for QueryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::WrongLength {
                what,
                expected,
                got,
            } => write!(f, "{what}: expected length {expected}, got {got}"),
            Self::NonFinite { what, index } => write!(f, "{what}[{index}] is not finite"),
            Self::OutOfGrid {
                axis,
                value,
                min,
                max,
            } => write!(
                f,
                "position {} = {value} m is outside the grid [{min}, {max}] m",
                if *axis == 0 { "x" } else { "y" }
            ),
        }
    }
}

impl core::error::Error for QueryError {}

/// Why a map could not be built, fitted, loaded or saved. Fields name what and where: `row`
/// is the 0-based index of the measurement or data record (CSV header not counted),
/// `column` the column name, nodes by their coordinates [m].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ComplianceMapError {
    /// An axis has fewer than 2 nodes.
    TooFewNodes {
        /// "x" or "y".
        axis: &'static str,
        /// Number of nodes.
        count: usize,
    },
    /// Node coordinates are not strictly increasing.
    NotIncreasing {
        /// "x" or "y".
        axis: &'static str,
        /// Index of the first node not above its predecessor.
        index: usize,
    },
    /// NaN or an infinity in a coordinate or coefficient array.
    NonFiniteValue {
        /// "x", "y", "slopes" or "offsets".
        what: &'static str,
        /// Index of the first bad entry.
        index: usize,
    },
    /// A number of force or displacement axes outside `1..=MAX_AXES`.
    BadAxisCount {
        /// "n_force" or "n_displacement".
        what: &'static str,
        /// The count given.
        count: usize,
    },
    /// An array has the wrong length.
    WrongLength {
        /// Which array.
        what: &'static str,
        /// Expected length (or the length it must be a multiple of).
        expected: usize,
        /// Length received.
        got: usize,
    },
    /// A node index outside the grid.
    NodeOutOfRange {
        /// Index along x.
        i: usize,
        /// Index along y.
        j: usize,
    },
    /// A query made while building (e.g. cross-validation) failed.
    Query(QueryError),
    /// A measurement or table value is NaN, infinite or missing.
    NonFinite {
        /// Record index (0-based).
        row: usize,
        /// Column name.
        column: &'static str,
    },
    /// A measurement's force axis is not below `n_force`.
    ForceAxisOutOfRange {
        /// Record index.
        row: usize,
        /// The axis given.
        force_axis: usize,
        /// Number of force axes of the fit.
        n_force: usize,
    },
    /// Fewer than 2 distinct force levels for one line fit (Eq. 12 needs >= 2).
    TooFewForceLevels {
        /// Node x [m].
        node_x: f64,
        /// Node y [m].
        node_y: f64,
        /// Force axis.
        force_axis: usize,
        /// Distinct force levels found (0 if the axis was never loaded at this node).
        levels: usize,
    },
    /// The measured positions do not form a rectilinear grid: fewer than half of the
    /// `distinct_x * distinct_y` nodes were measured.
    NotRectilinear {
        /// Distinct nodes measured.
        nodes: usize,
        /// Distinct x coordinates.
        distinct_x: usize,
        /// Distinct y coordinates.
        distinct_y: usize,
    },
    /// Coordinates chain within the position tolerance into a grid line wider than the
    /// tolerance: the node they belong to is ambiguous.
    AmbiguousCoordinate {
        /// "x" or "y".
        axis: &'static str,
        /// Lowest coordinate of the chain [m].
        low: f64,
        /// Highest coordinate of the chain [m].
        high: f64,
        /// The tolerance [m].
        tolerance: f64,
    },
    /// The same node, force axis and force level appear twice (average repeated trials
    /// before fitting).
    DuplicateMeasurement {
        /// The second occurrence.
        row: usize,
        /// The first occurrence.
        previous_row: usize,
    },
    /// A coefficient table lists the same node twice.
    DuplicateNode {
        /// The second occurrence.
        row: usize,
        /// The first occurrence.
        previous_row: usize,
    },
    /// A grid node has no data.
    MissingNode {
        /// Node x [m].
        x: f64,
        /// Node y [m].
        y: f64,
    },
    /// A required column is absent from a CSV header.
    MissingColumn {
        /// Column name.
        column: &'static str,
    },
    /// A CSV field is not a number (or not a valid force axis).
    BadNumber {
        /// Record index.
        row: usize,
        /// Column name.
        column: &'static str,
    },
    /// Two-point input: the measurement points coincide or the spacing is not positive.
    BadTwoPoint {
        /// The spacing |P_u P_l| given [m].
        spacing: f64,
    },
    /// An unknown unit name.
    #[cfg(feature = "alloc")]
    UnknownUnit {
        /// "force" or "length".
        quantity: &'static str,
        /// The name given.
        unit: String,
    },
    /// The CSV reader failed (malformed record, wrong field count, I/O).
    #[cfg(feature = "alloc")]
    Csv {
        /// 1-based line, when known.
        line: Option<u64>,
        /// The reader's message.
        message: String,
    },
    /// The JSON text is malformed or misses fields.
    #[cfg(feature = "alloc")]
    Json {
        /// The parser's message.
        message: String,
    },
    /// A JSON map of another format version.
    UnsupportedVersion {
        /// The version found.
        found: u64,
    },
    /// A JSON map records units other than SI.
    #[cfg(feature = "alloc")]
    UnexpectedUnits {
        /// Which quantity.
        quantity: &'static str,
        /// The unit recorded.
        found: String,
    },
}

impl fmt::Display for ComplianceMapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use ComplianceMapError as E;
        match self {
            E::TooFewNodes { axis, count } => {
                write!(
                    f,
                    "grid axis {axis} has {count} node(s); at least 2 are needed"
                )
            }
            E::NotIncreasing { axis, index } => write!(
                f,
                "grid axis {axis}: node {index} is not above node {}",
                index.saturating_sub(1)
            ),
            E::NonFiniteValue { what, index } => write!(f, "{what}[{index}] is not finite"),
            E::BadAxisCount { what, count } => {
                write!(f, "{what} = {count}; it must be in 1..={MAX_AXES}")
            }
            E::WrongLength {
                what,
                expected,
                got,
            } => write!(f, "{what}: expected length {expected}, got {got}"),
            E::NodeOutOfRange { i, j } => write!(f, "node ({i}, {j}) is outside the grid"),
            E::Query(e) => write!(f, "query failed: {e}"),
            E::NonFinite { row, column } => {
                write!(f, "row {row}, column {column}: value is not finite")
            }
            E::ForceAxisOutOfRange {
                row,
                force_axis,
                n_force,
            } => write!(
                f,
                "row {row}: force axis {force_axis} is not below n_force = {n_force}"
            ),
            E::TooFewForceLevels {
                node_x,
                node_y,
                force_axis,
                levels,
            } => write!(
                f,
                "node ({node_x}, {node_y}) m, force axis {force_axis}: {levels} distinct force \
                 level(s); a line fit needs at least 2"
            ),
            E::NotRectilinear {
                nodes,
                distinct_x,
                distinct_y,
            } => write!(
                f,
                "positions do not form a rectilinear grid: {nodes} nodes measured on \
                 {distinct_x} x {distinct_y} distinct coordinates"
            ),
            E::AmbiguousCoordinate {
                axis,
                low,
                high,
                tolerance,
            } => write!(
                f,
                "{axis} coordinates from {low} to {high} m chain within the tolerance \
                 {tolerance} m but span more than it: ambiguous grid line"
            ),
            E::DuplicateMeasurement { row, previous_row } => write!(
                f,
                "row {row} repeats the node, force axis and force of row {previous_row}"
            ),
            E::DuplicateNode { row, previous_row } => {
                write!(f, "row {row} repeats the node of row {previous_row}")
            }
            E::MissingNode { x, y } => write!(f, "grid node ({x}, {y}) m has no data"),
            E::MissingColumn { column } => write!(f, "missing column {column:?}"),
            E::BadNumber { row, column } => {
                write!(f, "row {row}, column {column}: not a valid number")
            }
            E::BadTwoPoint { spacing } => write!(
                f,
                "two-point input: spacing |P_u P_l| = {spacing} m must be positive and finite"
            ),
            #[cfg(feature = "alloc")]
            E::UnknownUnit { quantity, unit } => write!(f, "unknown {quantity} unit {unit:?}"),
            #[cfg(feature = "alloc")]
            E::Csv { line, message } => match line {
                Some(l) => write!(f, "CSV line {l}: {message}"),
                None => write!(f, "CSV: {message}"),
            },
            #[cfg(feature = "alloc")]
            E::Json { message } => write!(f, "JSON: {message}"),
            E::UnsupportedVersion { found } => write!(
                f,
                "compliance map format_version {found} is not supported (expected 1)"
            ),
            #[cfg(feature = "alloc")]
            E::UnexpectedUnits { quantity, found } => {
                write!(f, "JSON map records {quantity} in {found:?}; expected SI")
            }
        }
    }
}

impl core::error::Error for ComplianceMapError {}

/// Force unit of a file. Moments (force axes 3..5) are in this unit times the length unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ForceUnit {
    /// Newton.
    #[default]
    Newton,
    /// Kilogram-force, 9.80665 N.
    KilogramForce,
}

impl ForceUnit {
    /// Newtons per unit.
    pub fn to_newton(self) -> f64 {
        match self {
            Self::Newton => 1.0,
            Self::KilogramForce => STANDARD_GRAVITY,
        }
    }
    /// Parses "N" or "kgf" (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        if s.eq_ignore_ascii_case("n") {
            Some(Self::Newton)
        } else if s.eq_ignore_ascii_case("kgf") {
            Some(Self::KilogramForce)
        } else {
            None
        }
    }
}

/// Length unit of a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthUnit {
    /// Metre.
    #[default]
    Metre,
    /// Millimetre.
    Millimetre,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn to_metre(self) -> f64 {
        match self {
            Self::Metre => 1.0,
            Self::Millimetre => 1e-3,
        }
    }
    /// Parses "m" or "mm" (case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        if s.eq_ignore_ascii_case("m") {
            Some(Self::Metre)
        } else if s.eq_ignore_ascii_case("mm") {
            Some(Self::Millimetre)
        } else {
            None
        }
    }
}

/// Borrowed, allocation-free compliance map: the real-time lookup.
///
/// Coefficient layout (both `slopes` and `offsets`): node-major with `node = i * ny + j`
/// (`i` along x, `j` along y), then displacement axis `d`, then force axis `f`:
/// `index = (node * n_displacement + d) * n_force + f`.
#[derive(Debug, Clone, Copy)]
pub struct ComplianceMapView<'a> {
    x: grid::Axis<'a>,
    y: grid::Axis<'a>,
    n_force: usize,
    n_disp: usize,
    slopes: &'a [f64],
    offsets: &'a [f64],
    options: QueryOptions,
}

fn check_counts(n_force: usize, n_disp: usize) -> Result<(), ComplianceMapError> {
    for (what, count) in [("n_force", n_force), ("n_displacement", n_disp)] {
        if count == 0 || count > MAX_AXES {
            return Err(ComplianceMapError::BadAxisCount { what, count });
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
) -> Result<(), ComplianceMapError> {
    let expected = nodes * n_force * n_disp;
    for (what, v) in [("slopes", slopes), ("offsets", offsets)] {
        if v.len() != expected {
            return Err(ComplianceMapError::WrongLength {
                what,
                expected,
                got: v.len(),
            });
        }
        if let Some(index) = v.iter().position(|c| !c.is_finite()) {
            return Err(ComplianceMapError::NonFiniteValue { what, index });
        }
    }
    Ok(())
}

impl<'a> ComplianceMapView<'a> {
    /// Checks and wraps borrowed tables: `x` (nx), `y` (ny) node coordinates [m], strictly
    /// increasing; `slopes` and `offsets` of length `nx * ny * n_displacement * n_force` in
    /// the layout of the type's documentation. O(nx + ny + coefficients), no allocation.
    pub fn new(
        x: &'a [f64],
        y: &'a [f64],
        n_force: usize,
        n_displacement: usize,
        slopes: &'a [f64],
        offsets: &'a [f64],
    ) -> Result<Self, ComplianceMapError> {
        check_counts(n_force, n_displacement)?;
        let xi = grid::check_axis("x", x)?;
        let yi = grid::check_axis("y", y)?;
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
            options: QueryOptions::default(),
        })
    }

    /// The same view with other default query options.
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
    /// Node x coordinates [m].
    pub fn x(&self) -> &'a [f64] {
        self.x.nodes
    }
    /// Node y coordinates [m].
    pub fn y(&self) -> &'a [f64] {
        self.y.nodes
    }
}

/// Square root usable without `std`.
#[cfg(feature = "alloc")]
#[inline]
fn sqrt(v: f64) -> f64 {
    nalgebra::ComplexField::sqrt(v)
}

/// Owning compliance map (`alloc`): grid, per-node line coefficients, default query options
/// and, when fitted, the per-node fit statistics. See the module documentation for units and
/// [`ComplianceMapView`] for the coefficient layout.
#[cfg(feature = "alloc")]
#[derive(Debug, Clone, PartialEq)]
pub struct ComplianceMap {
    x: Vec<f64>,
    y: Vec<f64>,
    x_inv_step: f64,
    y_inv_step: f64,
    n_force: usize,
    n_disp: usize,
    slopes: Vec<f64>,
    offsets: Vec<f64>,
    options: QueryOptions,
    fit: Option<Vec<NodeFit>>,
}

#[cfg(feature = "alloc")]
impl ComplianceMap {
    /// Builds a map from node coordinates `x` (nx), `y` (ny) [m] and `slopes`, `offsets`
    /// (`nx * ny * n_displacement * n_force`, SI) in the layout of [`ComplianceMapView`].
    pub fn new(
        x: Vec<f64>,
        y: Vec<f64>,
        n_force: usize,
        n_displacement: usize,
        slopes: Vec<f64>,
        offsets: Vec<f64>,
    ) -> Result<Self, ComplianceMapError> {
        let v = ComplianceMapView::new(&x, &y, n_force, n_displacement, &slopes, &offsets)?;
        let (x_inv_step, y_inv_step) = (v.x.inv_step, v.y.inv_step);
        Ok(Self {
            x,
            y,
            x_inv_step,
            y_inv_step,
            n_force,
            n_disp: n_displacement,
            slopes,
            offsets,
            options: QueryOptions::default(),
            fit: None,
        })
    }

    /// The allocation-free view used for queries (O(1), nothing checked again).
    #[inline]
    pub fn view(&self) -> ComplianceMapView<'_> {
        ComplianceMapView {
            x: grid::Axis {
                nodes: &self.x,
                inv_step: self.x_inv_step,
            },
            y: grid::Axis {
                nodes: &self.y,
                inv_step: self.y_inv_step,
            },
            n_force: self.n_force,
            n_disp: self.n_disp,
            slopes: &self.slopes,
            offsets: &self.offsets,
            options: self.options,
        }
    }

    /// Displacement [m | rad] at `position` `[x, y]` [m] under `force` [N | N m] into `out`,
    /// with the map's default options (Eq. 9-10 at nodes, Eq. 14 or cubic between them).
    /// Allocation-free, never panics. See [`ComplianceMapView::displacement_with`].
    #[inline]
    pub fn displacement(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
    ) -> Result<QueryStatus, QueryError> {
        self.view()
            .displacement_with(position, force, out, self.options)
    }

    /// [`Self::displacement`] with explicit options for this query.
    #[inline]
    pub fn displacement_with(
        &self,
        position: [f64; 2],
        force: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<QueryStatus, QueryError> {
        self.view().displacement_with(position, force, out, options)
    }

    /// Many queries at once; see [`ComplianceMapView::displacement_batch`].
    pub fn displacement_batch(
        &self,
        positions: &[f64],
        stride: usize,
        forces: &[f64],
        out: &mut [f64],
        options: QueryOptions,
    ) -> Result<BatchSummary, BatchError> {
        self.view()
            .displacement_batch(positions, stride, forces, out, options)
    }

    /// Displacement at node `(i, j)` from its own lines (Eq. 9-10), no interpolation.
    pub fn node_displacement(
        &self,
        i: usize,
        j: usize,
        force: &[f64],
        out: &mut [f64],
    ) -> Result<(), ComplianceMapError> {
        let (nf, nd) = (self.n_force, self.n_disp);
        if force.len() != nf || out.len() != nd {
            return Err(ComplianceMapError::WrongLength {
                what: if force.len() != nf { "force" } else { "out" },
                expected: if force.len() != nf { nf } else { nd },
                got: if force.len() != nf {
                    force.len()
                } else {
                    out.len()
                },
            });
        }
        if i >= self.x.len() || j >= self.y.len() {
            return Err(ComplianceMapError::NodeOutOfRange { i, j });
        }
        let start = (i * self.y.len() + j) * nd * nf;
        let range = start..start + nd * nf;
        let (Some(s), Some(o)) = (self.slopes.get(range.clone()), self.offsets.get(range)) else {
            return Err(ComplianceMapError::NodeOutOfRange { i, j });
        };
        for ((out_d, s_row), o_row) in out
            .iter_mut()
            .zip(s.chunks_exact(nf))
            .zip(o.chunks_exact(nf))
        {
            *out_d = s_row
                .iter()
                .zip(o_row)
                .zip(force)
                .map(|((s, o), f)| s * f + o)
                .sum();
        }
        Ok(())
    }

    /// Slope of displacement axis `d` w.r.t. force axis `f` at node `(i, j)` [m/N].
    pub fn slope(&self, i: usize, j: usize, d: usize, f: usize) -> Option<f64> {
        self.coefficient(&self.slopes, i, j, d, f)
    }
    /// Offset of displacement axis `d` in the line of force axis `f` at node `(i, j)` [m].
    pub fn offset(&self, i: usize, j: usize, d: usize, f: usize) -> Option<f64> {
        self.coefficient(&self.offsets, i, j, d, f)
    }
    fn coefficient(&self, v: &[f64], i: usize, j: usize, d: usize, f: usize) -> Option<f64> {
        if i >= self.x.len() || j >= self.y.len() || d >= self.n_disp || f >= self.n_force {
            return None;
        }
        v.get(((i * self.y.len() + j) * self.n_disp + d) * self.n_force + f)
            .copied()
    }

    /// All slopes in the layout of [`ComplianceMapView`] [m/N].
    pub fn slopes(&self) -> &[f64] {
        &self.slopes
    }
    /// All offsets in the layout of [`ComplianceMapView`] [m].
    pub fn offsets(&self) -> &[f64] {
        &self.offsets
    }
    /// Node x coordinates [m].
    pub fn x(&self) -> &[f64] {
        &self.x
    }
    /// Node y coordinates [m].
    pub fn y(&self) -> &[f64] {
        &self.y
    }
    /// Number of force axes.
    pub fn n_force(&self) -> usize {
        self.n_force
    }
    /// Number of displacement axes.
    pub fn n_displacement(&self) -> usize {
        self.n_disp
    }
    /// Default query options.
    pub fn options(&self) -> QueryOptions {
        self.options
    }
    /// Sets the default query options.
    pub fn set_options(&mut self, options: QueryOptions) {
        self.options = options;
    }
    /// The same map with other default query options.
    pub fn with_options(mut self, options: QueryOptions) -> Self {
        self.options = options;
        self
    }
    /// Per-node fit statistics (node order `i * ny + j`), when the map was fitted.
    pub fn fit_stats(&self) -> Option<&[NodeFit]> {
        self.fit.as_deref()
    }
    pub(crate) fn set_fit_stats(&mut self, fit: Option<Vec<NodeFit>>) {
        self.fit = fit;
    }

    /// The map without the grid line `x = x_k` (`along_x`) or `y = y_k`.
    pub(crate) fn without_line(&self, along_x: bool, k: usize) -> Result<Self, ComplianceMapError> {
        let (nx, ny) = (self.x.len(), self.y.len());
        let block = self.n_force * self.n_disp;
        let keep = |i: usize, j: usize| if along_x { i != k } else { j != k };
        let mut slopes = Vec::with_capacity(self.slopes.len());
        let mut offsets = Vec::with_capacity(self.offsets.len());
        for i in 0..nx {
            for j in 0..ny {
                if keep(i, j) {
                    let r = (i * ny + j) * block..(i * ny + j + 1) * block;
                    slopes.extend_from_slice(self.slopes.get(r.clone()).unwrap_or(&[]));
                    offsets.extend_from_slice(self.offsets.get(r).unwrap_or(&[]));
                }
            }
        }
        let drop = |v: &[f64], skip: bool| -> Vec<f64> {
            v.iter()
                .enumerate()
                .filter(|(i, _)| !skip || *i != k)
                .map(|(_, c)| *c)
                .collect()
        };
        let m = Self::new(
            drop(&self.x, along_x),
            drop(&self.y, !along_x),
            self.n_force,
            self.n_disp,
            slopes,
            offsets,
        )?;
        Ok(m.with_options(self.options))
    }
}
