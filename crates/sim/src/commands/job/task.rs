//! What `job` has read and checked, for its run and its outputs.

use deflect_core::machining::Program;
use deflect_core::machining::job::Job;

use crate::cli::JobArgs;

/// Everything `job` needs, read and checked.
pub struct JobTask {
    pub(crate) job: Job,
    pub(crate) program: Program,
    pub(crate) program_name: String,
    pub(crate) robot_name: String,
    pub(crate) seed: Vec<f64>,
    /// The spin search's result and its wall time \[s\] (`--spin optimize`).
    pub(crate) spin: Option<(deflect_core::machining::spin::SpinPlan, f64)>,
    /// The setup's tool's end (five-axis programs): --shape, or the program's first
    /// `CUTTER/`.
    pub(crate) shape: deflect_core::machining::profile::ToolShape,
}

/// The five-axis pass's options of the flags: the stock's depth, the setup's tool's end, the
/// tools' length.
pub(crate) fn five_axis_options(
    a: &JobArgs,
    shape: deflect_core::machining::profile::ToolShape,
) -> deflect_core::machining::five_axis::Options {
    deflect_core::machining::five_axis::Options {
        depth: a.stock_depth * 1e-3,
        shape,
        length: a.flute_length * 1e-3,
        ..deflect_core::machining::five_axis::Options::default()
    }
}
