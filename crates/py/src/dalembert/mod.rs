//! The D'Alembert correctors of deflect-core's `dalembert` module: `DalembertCorrector`
//! ([`parallel`]: the paper's five-bar with a compliance map) and `SerialDalembertCorrector`
//! ([`serial`]: any serial arm in 6-D through its virtual-joint model).

use pyo3::prelude::*;

pub mod delta;
pub mod parallel;
pub mod serial;

/// Adds both corrector classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    parallel::register(m)?;
    delta::register(m)?;
    serial::register(m)
}
