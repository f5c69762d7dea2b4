//! Python bindings of deflect: thin wrappers that convert numpy arrays, call deflect-core
//! and map its errors onto one exception tree rooted in `ValueError`.
//!
//! ```text
//! ValueError
//! └── deflect.DeflectError
//!     ├── deflect.LoadError        malformed or inconsistent files (URDF, TOML, CSV, JSON)
//!     ├── deflect.InputError       wrong shapes, NaN/inf, out-of-range inputs
//!     ├── deflect.SingularError    singular pose: no unique correction
//!     └── deflect.ConvergenceError an iterative solve missed its tolerance
//! ```
// Bindings must not crash the interpreter: errors become Python exceptions.
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![deny(missing_docs)]
// reason: the doc comments of this crate are the Python docstrings (pyo3 copies them into
// `__doc__` for `help()`), so unit brackets such as [m] are plain text there, not rustdoc links.
#![allow(rustdoc::broken_intra_doc_links)]

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

mod args;
mod batch;
mod compensation;
mod compliance_map;
mod convert;
mod dalembert;
mod dalembert_serial;
mod drivetrain;
mod field;
mod identification;
mod mechanism;
mod motion;
mod pickle;
mod pose_motion;
mod posture;
mod vjm;

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

#[pymodule]
fn _deflect(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("DeflectError", py.get_type::<DeflectError>())?;
    m.add("LoadError", py.get_type::<LoadError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("SingularError", py.get_type::<SingularError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    vjm::register(m)?;
    compensation::register(m)?;
    identification::register(m)?;
    compliance_map::register(m)?;
    field::register(m)?;
    motion::register(m)?;
    mechanism::register(m)?;
    dalembert::register(m)?;
    dalembert_serial::register(m)?;
    pose_motion::register(m)?;
    drivetrain::register(m)?;
    posture::register(m)?;
    Ok(())
}
