//! Status codes of the C API, their messages, and the one mapping from deflect-core's three
//! error types (build, load, tick) and its placement status to C codes.

use std::ffi::c_char;

use deflect_core::{BuildError, LoadError, Placement, TickError};

/// Result of every fallible deflect function: `DEFLECT_OK` (0) on success, a negative
/// `DEFLECT_ERR_*` code otherwise (in the style of ruckig's `Result`).
pub type DeflectStatus = i32;

/// Success.
pub const DEFLECT_OK: DeflectStatus = 0;
/// A required pointer argument (handle, input or output array, string) is NULL.
pub const DEFLECT_ERR_NULL: DeflectStatus = -1;
/// An input holds NaN or an infinity (joints, wrench, position, force, acceleration, time,
/// path point, tolerance).
pub const DEFLECT_ERR_NON_FINITE: DeflectStatus = -2;
/// An array length argument does not match (joints vs. the robot's dof, force and output
/// lengths vs. the map's axes, too few or too many path points).
pub const DEFLECT_ERR_WRONG_LENGTH: DeflectStatus = -3;
/// A file could not be read or parsed, or its content is invalid (robot URDF/TOML,
/// compliance map CSV/JSON). The loader's `err` buffer holds the message.
pub const DEFLECT_ERR_LOAD: DeflectStatus = -4;
/// A compliance-map query fell outside the map's grid and the map's policy is
/// `DEFLECT_OUT_OF_GRID_ERROR`.
pub const DEFLECT_ERR_OUT_OF_GRID: DeflectStatus = -5;
/// The mechanism cannot reach the commanded point.
pub const DEFLECT_ERR_OUT_OF_WORKSPACE: DeflectStatus = -6;
/// The pose is singular or too close to a singularity (no unique inverse kinematics or joint
/// correction).
pub const DEFLECT_ERR_SINGULAR: DeflectStatus = -7;
/// An iterative solve did not reach its tolerance within its iteration budget.
pub const DEFLECT_ERR_NOT_CONVERGED: DeflectStatus = -8;
/// A parameter is out of its range: a unit or option code, motion limits, g level, sampling
/// rate, mass, robot geometry, tolerance, or a string that is not UTF-8.
pub const DEFLECT_ERR_INVALID_ARGUMENT: DeflectStatus = -9;
/// The compliance map's force/displacement axes do not fit the call (the D'Alembert corrector
/// of the planar robot needs a 2-force, 2-displacement map).
pub const DEFLECT_ERR_MAP_DIMENSION: DeflectStatus = -10;
/// A per-tick result overflowed to NaN or an infinity although every input was finite
/// (inputs far outside the model's physical range, such as a wrench of 1e308 N).
pub const DEFLECT_ERR_NON_FINITE_OUTPUT: DeflectStatus = -11;
/// The contour tracer's tool did not move along the edge (Eq. 21 has no direction).
pub const DEFLECT_ERR_NO_EDGE_MOTION: DeflectStatus = -12;
/// A joint command falls outside the robot's joint limits.
pub const DEFLECT_ERR_JOINT_LIMIT: DeflectStatus = -13;
/// A call would exceed its documented memory or time budget (sample count, iterations).
pub const DEFLECT_ERR_BUDGET: DeflectStatus = -14;
/// A workspace was made for a model of other dimensions.
pub const DEFLECT_ERR_MODEL_MISMATCH: DeflectStatus = -15;
/// An error this version of the C API does not classify (a newer deflect-core error kind).
pub const DEFLECT_ERR_OTHER: DeflectStatus = -98;
/// A Rust panic was caught at the boundary (a bug in deflect: please report it). Outputs are
/// unspecified; the handles involved may be destroyed safely.
pub const DEFLECT_ERR_PANIC: DeflectStatus = -99;

/// Query/model status: the position was inside the grid.
pub const DEFLECT_QUERY_INSIDE: i32 = 0;
/// Query/model status: the position was outside and was clamped.
pub const DEFLECT_QUERY_CLAMPED: i32 = 1;
/// Query/model status: the position was outside and was extrapolated.
pub const DEFLECT_QUERY_EXTRAPOLATED: i32 = 2;

/// The library version, a static NUL-terminated string such as "0.1.0".
#[unsafe(no_mangle)]
pub extern "C" fn deflect_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// A static NUL-terminated English description of a status code ("ok", "null pointer", ...;
/// "unknown status" for a code this library does not define). Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn deflect_status_message(status: DeflectStatus) -> *const c_char {
    let s: &'static str = match status {
        DEFLECT_OK => "ok\0",
        DEFLECT_ERR_NULL => "null pointer argument\0",
        DEFLECT_ERR_NON_FINITE => "input is NaN or infinite\0",
        DEFLECT_ERR_WRONG_LENGTH => "array length does not match\0",
        DEFLECT_ERR_LOAD => "file could not be loaded\0",
        DEFLECT_ERR_OUT_OF_GRID => "position outside the compliance map's grid\0",
        DEFLECT_ERR_OUT_OF_WORKSPACE => "point outside the robot's workspace\0",
        DEFLECT_ERR_SINGULAR => "singular or near-singular pose\0",
        DEFLECT_ERR_NOT_CONVERGED => "iterative solve did not converge\0",
        DEFLECT_ERR_INVALID_ARGUMENT => "invalid argument\0",
        DEFLECT_ERR_MAP_DIMENSION => "compliance map has the wrong number of axes\0",
        DEFLECT_ERR_NON_FINITE_OUTPUT => "result overflowed: inputs far out of range\0",
        DEFLECT_ERR_NO_EDGE_MOTION => "no motion along the edge\0",
        DEFLECT_ERR_JOINT_LIMIT => "joint command outside its limits\0",
        DEFLECT_ERR_BUDGET => "request exceeds its documented budget\0",
        DEFLECT_ERR_MODEL_MISMATCH => "workspace made for another model\0",
        DEFLECT_ERR_OTHER => "unclassified error\0",
        DEFLECT_ERR_PANIC => "internal error (panic caught)\0",
        _ => "unknown status\0",
    };
    s.as_ptr().cast()
}

/// The C code of a per-tick error: one code per [`TickError`] variant.
pub(crate) fn tick_status(e: &TickError) -> DeflectStatus {
    match e {
        TickError::WrongLength { .. } => DEFLECT_ERR_WRONG_LENGTH,
        TickError::NonFinite { .. } => DEFLECT_ERR_NON_FINITE,
        TickError::NonFiniteOutput { .. } => DEFLECT_ERR_NON_FINITE_OUTPUT,
        TickError::InvalidArgument { .. } => DEFLECT_ERR_INVALID_ARGUMENT,
        TickError::OutOfGrid { .. } => DEFLECT_ERR_OUT_OF_GRID,
        TickError::OutOfWorkspace { .. } => DEFLECT_ERR_OUT_OF_WORKSPACE,
        TickError::Singular { .. } => DEFLECT_ERR_SINGULAR,
        TickError::NotConverged { .. } => DEFLECT_ERR_NOT_CONVERGED,
        TickError::NoEdgeMotion => DEFLECT_ERR_NO_EDGE_MOTION,
        TickError::JointLimit { .. } => DEFLECT_ERR_JOINT_LIMIT,
        TickError::Budget { .. } => DEFLECT_ERR_BUDGET,
        TickError::ModelMismatch { .. } => DEFLECT_ERR_MODEL_MISMATCH,
        _ => DEFLECT_ERR_OTHER,
    }
}

/// The C code of a build error: the kind of value that was wrong.
pub(crate) fn build_status(e: &BuildError) -> DeflectStatus {
    match e {
        BuildError::NonFinite { .. } => DEFLECT_ERR_NON_FINITE,
        BuildError::WrongLength { .. }
        | BuildError::Capacity { .. }
        | BuildError::TooFew { .. }
        | BuildError::DofMismatch { .. } => DEFLECT_ERR_WRONG_LENGTH,
        BuildError::MapDimension { .. } => DEFLECT_ERR_MAP_DIMENSION,
        BuildError::Singular { .. } => DEFLECT_ERR_SINGULAR,
        BuildError::InvalidParameter { value, .. } | BuildError::InvalidEntry { value, .. }
            if !value.is_finite() =>
        {
            DEFLECT_ERR_NON_FINITE
        }
        _ => DEFLECT_ERR_INVALID_ARGUMENT,
    }
}

/// A build error as a loader's `(status, message)`.
pub(crate) fn build_failure(e: BuildError) -> (DeflectStatus, String) {
    (build_status(&e), e.to_string())
}

/// A load error as a loader's `(status, message)`.
pub(crate) fn load_failure(e: LoadError) -> (DeflectStatus, String) {
    (DEFLECT_ERR_LOAD, e.to_string())
}

/// The C code of a placement (`DEFLECT_QUERY_*`).
pub(crate) fn placement_code(p: Placement) -> i32 {
    match p {
        Placement::Inside => DEFLECT_QUERY_INSIDE,
        Placement::Clamped => DEFLECT_QUERY_CLAMPED,
        Placement::Extrapolated => DEFLECT_QUERY_EXTRAPOLATED,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Codes no current entry point can provoke are still mapped as documented.
    #[test]
    fn every_tick_error_has_its_own_code() {
        let errors = [
            TickError::WrongLength {
                what: "q",
                expected: 6,
                got: 5,
            },
            TickError::NonFinite {
                what: "q",
                index: 0,
            },
            TickError::NonFiniteOutput {
                what: "d",
                index: 0,
            },
            TickError::InvalidArgument {
                what: "rate_hz",
                value: 0.0,
            },
            TickError::OutOfGrid {
                axis: 0,
                value: 1.0,
                min: 0.0,
                max: 0.5,
            },
            TickError::OutOfWorkspace {
                distance: 1.0,
                reach: 0.3,
            },
            TickError::Singular {
                what: "joint Jacobian",
                sigma_min: 0.0,
            },
            TickError::NotConverged {
                iterations: 3,
                residual: 1.0,
            },
            TickError::NoEdgeMotion,
            TickError::JointLimit {
                joint: 0,
                value: 4.0,
                lower: -3.0,
                upper: 3.0,
            },
            TickError::Budget {
                what: "samples",
                budget: "MAX_SAMPLES",
                limit: 1e7,
                requested: 1e9,
            },
            TickError::ModelMismatch {
                what: "dof",
                expected: 6,
                got: 5,
            },
        ];
        let mut codes: Vec<DeflectStatus> = errors.iter().map(tick_status).collect();
        assert!(codes.iter().all(|c| *c < 0 && *c != DEFLECT_ERR_OTHER));
        codes.sort_unstable();
        codes.dedup();
        assert_eq!(codes.len(), errors.len(), "two tick errors share a code");
        assert_eq!(tick_status(&errors[7]), DEFLECT_ERR_NOT_CONVERGED);
        assert_eq!(
            build_status(&BuildError::DofMismatch {
                what: "arm",
                expected: 6,
                got: 5
            }),
            DEFLECT_ERR_WRONG_LENGTH
        );
        for code in codes {
            // SAFETY: a static NUL-terminated string.
            let msg = unsafe { std::ffi::CStr::from_ptr(deflect_status_message(code)) };
            assert_ne!(msg.to_str().unwrap(), "unknown status", "code {code}");
        }
    }
}
