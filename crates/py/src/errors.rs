//! The one mapping of deflect-core's errors onto the exception tree (every wrapper maps core
//! errors through [`build_err`], [`load_err`] and [`tick_err`] or [`tick_err_at`]), the
//! exceptions the bindings raise themselves for shapes ([`shape_error`]), and the text of a
//! Python value in a message.
//!
//! ```text
//! ValueError
//! └── deflect.DeflectError
//!     ├── deflect.LoadError        malformed or inconsistent files (URDF, TOML, CSV, JSON)
//!     ├── deflect.InputError       wrong shapes, NaN/inf, out-of-range inputs
//!     ├── deflect.SingularError    singular pose: no unique correction
//!     └── deflect.ConvergenceError an iterative solve missed its tolerance
//! ```

use core::fmt::Display;

use deflect_core::{BuildError, LoadError as CoreLoadError, TickError};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(
    deflect,
    DeflectError,
    PyValueError,
    "Root of deflect's exceptions."
);
create_exception!(
    deflect,
    LoadError,
    DeflectError,
    "A file could not be loaded or validated."
);
create_exception!(
    deflect,
    InputError,
    DeflectError,
    "An input has the wrong shape or is not finite."
);
create_exception!(
    deflect,
    SingularError,
    DeflectError,
    "The pose is singular."
);
create_exception!(
    deflect,
    ConvergenceError,
    DeflectError,
    "An iterative solve did not converge."
);

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("DeflectError", py.get_type::<DeflectError>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("SingularError", py.get_type::<SingularError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    Ok(())
}

/// A model, configuration or fit that could not be built: `SingularError` for a singular
/// matrix parameter, `InputError` otherwise (budgets included).
pub fn build_err(e: BuildError) -> PyErr {
    match e {
        BuildError::Singular { .. } => SingularError::new_err(e.to_string()),
        _ => InputError::new_err(e.to_string()),
    }
}

/// A file that could not be read or validated: `LoadError`.
pub fn load_err(e: CoreLoadError) -> PyErr {
    LoadError::new_err(e.to_string())
}

/// A per-tick error: `SingularError` for a singular pose or stiffness and for a step without
/// edge motion, `ConvergenceError` for a solve that missed its tolerance, `InputError` for
/// everything else (shapes, NaN/inf, out of grid or workspace, budgets, joint limits,
/// overflowing outputs, invalid arguments, ...).
pub fn tick_err(e: TickError) -> PyErr {
    tick_exception(e, e.to_string())
}

/// [`tick_err`] with the message prefixed by where it happened (`"row 3"`, `"tick 17"`).
pub fn tick_err_at(context: impl Display, e: TickError) -> PyErr {
    tick_exception(e, format!("{context}: {e}"))
}

fn tick_exception(e: TickError, message: String) -> PyErr {
    match e {
        TickError::Singular { .. } | TickError::NoEdgeMotion => SingularError::new_err(message),
        TickError::NotConverged { .. } => ConvergenceError::new_err(message),
        // OutOfGrid, OutOfWorkspace, ModelMismatch, NonFiniteOutput, Budget, JointLimit,
        // InvalidArgument, WrongLength, NonFinite and any later variant.
        _ => InputError::new_err(message),
    }
}

/// A machining job that failed: the class of the per-sample error (`ConvergenceError` for
/// a pose out of reach, `SingularError`, `InputError`), the message naming the program line.
pub fn job_err(e: deflect_core::JobError) -> PyErr {
    match e {
        deflect_core::JobError::Setup(b) => build_err(b),
        deflect_core::JobError::AtLine { error, .. } => tick_exception(error, e.to_string()),
        _ => InputError::new_err(e.to_string()),
    }
}

/// A shape as Python prints it: `()`, `(6,)`, `(3, 6)`.
pub fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// `InputError`: `what` has the wrong shape.
pub fn shape_error(what: &str, expected: &str, got: &[usize]) -> PyErr {
    InputError::new_err(format!(
        "{what}: expected shape {expected}, got {}",
        shape_text(got)
    ))
}

/// Shortens the text of a Python value for a message (a huge integer has many digits).
pub fn short(o: &Bound<'_, PyAny>) -> String {
    let s = o
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "<unprintable>".to_string());
    if s.chars().count() > 48 {
        let head: String = s.chars().take(40).collect();
        format!("{head}... ({} characters)", s.chars().count())
    } else {
        s
    }
}

/// The Python type name of `o` (`complex`, `str`, `numpy.ndarray`).
pub fn type_name(o: &Bound<'_, PyAny>) -> String {
    o.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".to_string())
}
