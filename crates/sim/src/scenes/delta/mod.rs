//! The Delta robot scene: the D'Alembert correction of Paksoy, Dede and Kiper (2025) on the
//! high-acceleration parallel robot of industry, as on their five-bar: static tests at the
//! nodes of a 3-D grid over the workspace -> a 3-D compliance map fitted per node (Eq. 10-13)
//! -> a pick-and-place move at 5-10 g corrected every tick (Eq. 5, the map, IK), against the
//! same move uncorrected, on a flexible Delta in rapier ([`robot`]).

pub mod options;
pub mod output;
pub mod robot;
pub mod run;

pub use options::DeltaOptions;
pub use robot::{DeltaParams, DeltaSim};
pub use run::{DeltaResult, DeltaRun, delta, plan, run, static_check, static_tests};
