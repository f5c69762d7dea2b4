//! Tier 1: a model, configuration or fit could not be assembled.

use core::fmt;

use super::TickError;

/// A model, configuration or fit could not be assembled. No heap, `Copy`.
///
/// Fields name what was wrong and where (`what`, an index or element), the value given and
/// what was expected.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum BuildError {
    /// A fixed capacity of a real-time model was exceeded.
    Capacity {
        /// Which capacity ("elements", "joints", "springs", "masses", "points").
        what: &'static str,
        /// Its size.
        capacity: usize,
        /// How many were asked for (at least `capacity + 1`).
        got: usize,
    },
    /// A parameter or an array entry holds NaN or an infinity.
    NonFinite {
        /// Which parameter or array.
        what: &'static str,
        /// Index of the first non-finite entry (0 for a scalar).
        index: usize,
    },
    /// A scalar parameter is outside its range.
    InvalidParameter {
        /// The parameter.
        what: &'static str,
        /// Its value.
        value: f64,
        /// The range it must lie in, in words ("> 0", "in (0, 1\]").
        expected: &'static str,
    },
    /// An entry of a per-joint or per-axis array is outside its range.
    InvalidEntry {
        /// The array.
        what: &'static str,
        /// Index of the entry.
        index: usize,
        /// Its value.
        value: f64,
        /// The range it must lie in, in words.
        expected: &'static str,
    },
    /// An array has the wrong length.
    WrongLength {
        /// Which array.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length received.
        got: usize,
    },
    /// Too few items of something (nodes, points, measurements).
    TooFew {
        /// What was counted.
        what: &'static str,
        /// Least number needed.
        needed: usize,
        /// Number given.
        got: usize,
    },
    /// Two pieces that must agree in size do not (a drive train and its chain, a serial
    /// mechanism and its model).
    DofMismatch {
        /// Which piece.
        what: &'static str,
        /// Size it must have.
        expected: usize,
        /// Size it has.
        got: usize,
    },
    /// A joint axis is zero or not finite.
    ZeroAxis {
        /// Builder call index.
        element: usize,
    },
    /// A virtual-joint stiffness is zero, negative, sub-normal or NaN (`+inf` = rigid).
    NonPositiveStiffness {
        /// Builder call index.
        element: usize,
        /// 0, 1, 2 for the spring frame's x, y, z axis.
        axis: usize,
        /// The offending value \[N m / rad\].
        value: f64,
    },
    /// A matrix given as a model parameter is singular or not positive definite.
    Singular {
        /// Which matrix.
        what: &'static str,
        /// A measure of its distance to singularity (smallest eigenvalue or reciprocal
        /// condition), in the matrix's units.
        measure: f64,
    },
    /// Coordinates that must increase strictly do not.
    NotIncreasing {
        /// "x" or "y".
        what: &'static str,
        /// Index of the first entry not above its predecessor.
        index: usize,
    },
    /// A compliance map has other force/displacement dimensions than its user needs.
    MapDimension {
        /// Dimension needed (force and displacement).
        expected: usize,
        /// Force axes of the map.
        n_force: usize,
        /// Displacement axes of the map.
        n_displacement: usize,
    },
    /// A node index outside a compliance map's grid.
    NodeOutOfRange {
        /// Index along x.
        i: usize,
        /// Index along y.
        j: usize,
    },
    /// A measurement holds NaN or an infinity.
    NonFiniteMeasurement {
        /// Measurement (record) index.
        row: usize,
        /// The field ("x", "y", "force", "d0".."d5").
        column: &'static str,
    },
    /// A measurement's force axis is not below the fit's number of force axes.
    ForceAxisOutOfRange {
        /// Record index.
        row: usize,
        /// The axis given.
        force_axis: usize,
        /// Number of force axes of the fit.
        n_force: usize,
    },
    /// Fewer than 2 distinct force levels for one line fit (Eq. 12 of Paksoy et al. needs 2).
    TooFewForceLevels {
        /// Node x \[m\].
        node_x: f64,
        /// Node y \[m\].
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
        /// Lowest coordinate of the chain \[m\].
        low: f64,
        /// Highest coordinate of the chain \[m\].
        high: f64,
        /// The tolerance \[m\].
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
        /// Node x \[m\].
        x: f64,
        /// Node y \[m\].
        y: f64,
    },
    /// Fewer than 2 distinct force levels for one line fit at a node of an N-D grid.
    TooFewGridForceLevels {
        /// Node coordinates (the first `dims`; unused entries 0).
        node: [f64; 4],
        /// Grid dimensions.
        dims: usize,
        /// Force axis.
        force_axis: usize,
        /// Distinct levels found.
        levels: usize,
    },
    /// A node of an N-D grid has no data: its coordinates, the first `dims` of `node`.
    MissingGridNode {
        /// Node coordinates (unused entries 0).
        node: [f64; 4],
        /// Grid dimensions.
        dims: usize,
    },
    /// Two-point input: the measurement points coincide or the spacing is not positive.
    BadTwoPoint {
        /// The spacing |P_u P_l| given \[m\].
        spacing: f64,
    },
    /// A measurement names a virtual joint that does not exist.
    UnknownSpring {
        /// Measurement index.
        measurement: usize,
        /// Spring index given.
        spring: usize,
        /// Springs in the model.
        springs: usize,
    },
    /// A measurement was refused by the model it is evaluated with.
    BadMeasurement {
        /// Measurement index.
        measurement: usize,
        /// Why.
        error: TickError,
    },
    /// A query made while building (for example by a cross-validation) failed.
    Query(TickError),
    /// A solver used while building did not converge (an SVD's iteration budget).
    Numerical {
        /// Which solve.
        what: &'static str,
    },
    /// A request exceeds a documented memory or time budget (measurements, rows).
    Budget {
        /// What grows.
        what: &'static str,
        /// The name of the documented limit (`"MAX_MEASUREMENTS"`).
        budget: &'static str,
        /// The documented limit.
        limit: usize,
        /// What was asked for.
        requested: usize,
    },
    /// [`crate::motion::paper_limits`] knows 1..=5 g only.
    UnknownGLevel {
        /// The level asked for.
        g_level: u8,
    },
}

pub(super) fn axis_name(axis: usize) -> &'static str {
    ["x", "y", "z"].get(axis).copied().unwrap_or("?")
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Capacity {
                what,
                capacity,
                got,
            } => write!(
                f,
                "too many {what}: {got} given, the real-time model holds at most {capacity}"
            ),
            Self::NonFinite { what, index } => write!(f, "{what}[{index}] is not finite"),
            Self::InvalidParameter {
                what,
                value,
                expected,
            } => write!(f, "{what} is {value:?}; it must be {expected}"),
            Self::InvalidEntry {
                what,
                index,
                value,
                expected,
            } => write!(f, "{what}[{index}] is {value:?}; it must be {expected}"),
            Self::WrongLength {
                what,
                expected,
                got,
            } => write!(f, "{what}: expected length {expected}, got {got}"),
            Self::TooFew { what, needed, got } => {
                write!(f, "{got} {what}; at least {needed} are needed")
            }
            Self::DofMismatch {
                what,
                expected,
                got,
            } => write!(f, "{what} has {got} joints; the model has {expected}"),
            Self::ZeroAxis { element } => {
                write!(f, "element {element}: joint axis is zero or not finite")
            }
            Self::NonPositiveStiffness {
                element,
                axis,
                value,
            } => write!(
                f,
                "element {element}: stiffness about axis {} is {value:?}; it must be a normal \
                 number > 0 (inf = rigid)",
                axis_name(*axis)
            ),
            Self::Singular { what, measure } => write!(
                f,
                "{what} is singular or not positive definite (measure {measure:e})"
            ),
            Self::NotIncreasing { what, index } => write!(
                f,
                "grid axis {what}: node {index} is not above node {}",
                index.saturating_sub(1)
            ),
            Self::MapDimension {
                expected,
                n_force,
                n_displacement,
            } => write!(
                f,
                "compliance map has {n_force} force and {n_displacement} displacement axes; \
                 {expected} and {expected} are needed"
            ),
            Self::NodeOutOfRange { i, j } => write!(f, "node ({i}, {j}) is outside the grid"),
            Self::NonFiniteMeasurement { row, column } => {
                write!(f, "row {row}, column {column}: value is not finite")
            }
            Self::ForceAxisOutOfRange {
                row,
                force_axis,
                n_force,
            } => write!(
                f,
                "row {row}: force axis {force_axis} is not below n_force = {n_force}"
            ),
            Self::TooFewForceLevels {
                node_x,
                node_y,
                force_axis,
                levels,
            } => write!(
                f,
                "node ({node_x}, {node_y}) m, force axis {force_axis}: {levels} distinct force \
                 level(s); a line fit needs at least 2"
            ),
            Self::NotRectilinear {
                nodes,
                distinct_x,
                distinct_y,
            } => write!(
                f,
                "positions do not form a rectilinear grid: {nodes} nodes measured on \
                 {distinct_x} x {distinct_y} distinct coordinates"
            ),
            Self::AmbiguousCoordinate {
                axis,
                low,
                high,
                tolerance,
            } => write!(
                f,
                "{axis} coordinates from {low} to {high} m chain within the tolerance \
                 {tolerance} m but span more than it: ambiguous grid line"
            ),
            Self::DuplicateMeasurement { row, previous_row } => write!(
                f,
                "row {row} repeats the node, force axis and force of row {previous_row}"
            ),
            Self::DuplicateNode { row, previous_row } => {
                write!(f, "row {row} repeats the node of row {previous_row}")
            }
            Self::MissingNode { x, y } => write!(f, "grid node ({x}, {y}) m has no data"),
            Self::TooFewGridForceLevels {
                node,
                dims,
                force_axis,
                levels,
            } => {
                write!(f, "grid node (")?;
                for (k, v) in node.iter().take(*dims).enumerate() {
                    if k > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{v}")?;
                }
                write!(
                    f,
                    "), force axis {force_axis}: {levels} distinct force level(s); a line fit \
                     needs at least 2"
                )
            }
            Self::MissingGridNode { node, dims } => {
                write!(f, "grid node (")?;
                for (k, v) in node.iter().take(*dims).enumerate() {
                    if k > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{v}")?;
                }
                write!(f, ") has no data")
            }
            Self::BadTwoPoint { spacing } => write!(
                f,
                "two-point input: spacing |P_u P_l| = {spacing} m must be positive and finite"
            ),
            Self::UnknownSpring {
                measurement,
                spring,
                springs,
            } => write!(
                f,
                "measurement {measurement}: virtual joint {spring} does not exist (model has \
                 {springs})"
            ),
            Self::BadMeasurement { measurement, error } => {
                write!(f, "measurement {measurement}: {error}")
            }
            Self::Query(e) => write!(f, "query failed: {e}"),
            Self::Numerical { what } => write!(f, "{what}: the solver did not converge"),
            Self::Budget {
                what,
                budget,
                limit,
                requested,
            } => write!(
                f,
                "{requested} {what} requested; the limit is {budget} = {limit} {what}"
            ),
            Self::UnknownGLevel { g_level } => {
                write!(f, "the paper's motions exist for 1..=5 g, not {g_level} g")
            }
        }
    }
}

impl core::error::Error for BuildError {}

/// A finite scalar parameter that satisfies `ok`, else [`BuildError::InvalidParameter`]
/// (NaN and infinities included: the message shows the value).
pub(crate) fn param(
    what: &'static str,
    value: f64,
    ok: bool,
    expected: &'static str,
) -> Result<f64, BuildError> {
    if ok && value.is_finite() {
        Ok(value)
    } else {
        Err(BuildError::InvalidParameter {
            what,
            value,
            expected,
        })
    }
}

/// A frame's translation and quaternion (x, y, z, then i, j, k, w) all finite, else
/// [`BuildError::NonFinite`] naming `what` and the first bad entry.
pub(crate) fn check_frame(
    what: &'static str,
    t: &nalgebra::Isometry3<f64>,
) -> Result<(), BuildError> {
    match t
        .translation
        .vector
        .iter()
        .chain(t.rotation.coords.iter())
        .position(|v| !v.is_finite())
    {
        Some(index) => Err(BuildError::NonFinite { what, index }),
        None => Ok(()),
    }
}
