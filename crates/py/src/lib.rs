//! Python bindings of deflect: thin wrappers that convert numpy arrays (`arrays`) and
//! scalars (`scalars`, `args`), call deflect-core (which validates every value) and map its
//! errors onto one exception tree rooted in `ValueError` (`errors`). Batches run on every
//! core through one runner (`batch`).
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

use pyo3::prelude::*;

mod args;
mod arrays;
mod batch;
mod compensation;
mod compliance_map;
mod cutter;
mod dalembert;
mod dexel;
mod drivetrain;
mod errors;
mod field;
mod five_axis;
mod grid_map;
mod identification;
mod job_args;
mod kinematics;
mod machining;
mod machining_job;
mod machining_result;
mod map_common;
mod mechanism;
mod motion;
mod out;
mod pickle;
mod placement;
mod pose_motion;
mod posture;
mod program_state;
mod scalars;
mod tools;
mod vjm;

pub use errors::{ConvergenceError, DeflectError, InputError, LoadError, SingularError};

#[pymodule]
fn _deflect(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The budgets and bounds that errors name, under the same names.
    m.add("MAX_SAMPLES", deflect_core::motion::MAX_SAMPLES)?;
    m.add("MAX_TICKS", deflect_core::motion::MAX_TICKS)?;
    m.add("MAX_SPRING_ANGLE", deflect_core::vjm::MAX_SPRING_ANGLE)?;
    m.add("MAX_JOINT_POSITION", deflect_core::vjm::MAX_JOINT_POSITION)?;
    m.add("MAX_DURATION", deflect_core::motion::MAX_DURATION)?;
    m.add("MAX_DOF", deflect_core::vjm::MAX_DOF)?;
    m.add("MAX_SPRINGS", deflect_core::vjm::MAX_SPRINGS)?;
    m.add(
        "MAX_MEASUREMENTS",
        deflect_core::identification::MAX_MEASUREMENTS,
    )?;
    m.add("MAX_POINTS", deflect_core::motion::MAX_POINTS)?;
    m.add("MAX_ANGLES", deflect_core::posture::MAX_ANGLES)?;
    m.add("MAX_SEEDS", deflect_core::posture::MAX_SEEDS)?;
    m.add("MAX_DIRECTIONS", deflect_core::posture::MAX_DIRECTIONS)?;
    m.add("MAX_AXES", deflect_core::compliance_map::MAX_AXES)?;
    vjm::register(m)?;
    compensation::register(m)?;
    identification::register(m)?;
    compliance_map::register(m)?;
    grid_map::register(m)?;
    field::register(m)?;
    motion::register(m)?;
    mechanism::register(m)?;
    mechanism::register_delta(m)?;
    dalembert::register(m)?;
    pose_motion::register(m)?;
    drivetrain::register(m)?;
    posture::register(m)?;
    machining::register(m)?;
    dexel::register(m)?;
    machining_job::register(m)?;
    five_axis::register(m)?;
    placement::register(m)?;
    tools::register(m)?;
    Ok(())
}
