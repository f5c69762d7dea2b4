//! The D'Alembert correctors of deflect-core's `dalembert` module: `DalembertCorrector`
//! ([`parallel`]: the paper's five-bar with a compliance map) and `SerialDalembertCorrector`
//! ([`serial`]: any serial arm in 6-D through its virtual-joint model), and `DeltaCorrector`
//! ([`delta`]: a Delta with a 3-D map). The two parallel correctors share one code path
//! (`corrector`: the model, the locked tick state, a tick's inputs and its dict).

use pyo3::prelude::*;

mod corrector;
pub mod delta;
pub mod parallel;
pub mod serial;

/// Adds both corrector classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    parallel::register(m)?;
    delta::register(m)?;
    serial::register(m)
}
