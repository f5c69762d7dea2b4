//! Milling scenario for the online force-based compensation of Hähn and Weigold, "Hybrid
//! compliance compensation for path accuracy enhancement in robot machining" (2020), sec.
//! 2.2-2.6 and 3, on their robot: the 6-axis KUKA KR 300 R2500 of `robots/` as a flexible arm
//! in rapier (the serial testbed's [`crate::urdf_arm`]).
//!
//! * [`arm`]: the robot ([`MillingArm`]): the simulated arm, its sensor frame, the rigid pose
//!   IK of the commanded path and the model rebuilt with identified stiffnesses.
//! * [`sensor`]: the flange force/torque sensor with offsets, tool weight and noise.
//! * [`identification`]: the stiffnesses from frame-pair rotations and TCP deflections under
//!   static loads in rapier, and the sensor from unloaded readings at several orientations.
//! * [`options`]: the settings.
//! * [`run`](mod@run): a straight groove along +x at constant feed with the tool pointing down; a
//!   process force that steps up at cutter entry and down at exit acts at the TCP; the sensor
//!   reads it with an internal offset, the tool's weight and seeded Gaussian noise. Runs:
//!   uncompensated, Cartesian compensation ([`deflect_core::compensation::step`], measured
//!   forces only), compensation with pilot control (an offline force estimate leading the
//!   real force), and Cartesian compensation without sensor calibration. The correction is
//!   applied every control cycle through the arm's pose inverse kinematics; the robot answers a
//!   correction after a transport delay and a first-order servo lag. The compensator uses the
//!   identified values.
//! * [`output`]: summary table, CSV, JSON, MCAP log and plots.
//! * [`program`]: the paper's validation on a machining program (engagement where the
//!   simulated tool is; uncompensated, offline, Cartesian, hybrid, axis-specific); the
//!   parts of its control cycle in the private `cycle`.
//! * [`program_output`]: the program scenario's table, JSON, CSV and MCAP log.
//! * [`part_map`]: the machined part against the nominal one as a heat map (Fig. 10-13).

pub mod arm;
mod cycle;
pub mod five_axis;
pub mod identification;
pub mod options;
pub mod output;
pub mod part_map;
pub mod part_view;
pub mod program;
pub mod program_output;
pub mod run;
pub mod sensor;

pub use arm::{MillingArm, SpringInfo};
pub use identification::{
    JointEstimate, SensorEstimate, identify_sensor_calibration, identify_stiffness,
};
pub use options::MillingOptions;
pub use run::{Metrics, MillingResult, Mode, Run, Sample, milling, run};
pub use sensor::SensorParams;
