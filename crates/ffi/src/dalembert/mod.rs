//! The D'Alembert correctors of deflect-core's `dalembert` module: [`parallel`] (the paper's
//! five-bar with a compliance map), [`delta`] (a Delta robot with a 3-D map) and [`serial`] (any serial arm in 6-D through its
//! virtual-joint model). Each handle holds the core's `Model` and `Data`; the two parallel
//! correctors' handles share one code path (`corrector`: build and tick, generic over the task
//! dimension).

mod corrector;
pub mod delta;
pub mod parallel;
pub mod serial;
