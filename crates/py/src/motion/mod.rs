//! `deflect.plan_line`, `deflect.plan_polyline` and `deflect.Trajectory`: jerk-limited
//! rest-to-rest motions in 1..=8 coordinates (Cartesian points or joint vectors), planned
//! once and then evaluated at any time or sampled at a fixed rate, and trajectories built from
//! the user's own samples. The planning and the finite differences are deflect-core's.

use pyo3::prelude::*;

mod plan;
mod planner;
mod trajectory;

pub use trajectory::Trajectory;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<trajectory::Trajectory>()?;
    m.add_class::<planner::LinePlanner>()?;
    m.add_function(wrap_pyfunction!(trajectory::plan_line, m)?)?;
    m.add_function(wrap_pyfunction!(trajectory::plan_polyline, m)?)?;
    m.add_function(wrap_pyfunction!(trajectory::paper_limits, m)?)?;
    Ok(())
}
