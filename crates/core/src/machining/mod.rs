//! Robot machining: the program a CAM system writes, as moves in the workpiece frame
//! ([`Program`], read by [`crate::io::gcode`]), and the milling force it makes
//! ([`cutting`]: the mechanistic model of end milling; [`profile`]: of flat, ball and
//! bull-nose cutters along their edge), and the stock it cuts ([`stock`]: a
//! z-map lowered by a flat or ball end mill).
//!
//! This is the offline half of the hybrid compensation of Hähn and Weigold ("Hybrid
//! compliance compensation for path accuracy enhancement in robot machining", 2020, sec. 2.4):
//! "the motion commands stored in the robot program are combined with roughly estimated
//! cutting forces prior to the machining process".

#[cfg(feature = "alloc")]
pub mod chip;
pub mod cutting;
#[cfg(feature = "alloc")]
pub mod dexel;
#[cfg(feature = "alloc")]
pub mod engagement;
#[cfg(feature = "alloc")]
pub mod five_axis;
#[cfg(feature = "alloc")]
pub mod job;
pub mod kinematics;
#[cfg(feature = "alloc")]
pub mod path;
#[cfg(feature = "alloc")]
pub mod placement;
pub mod profile;
#[cfg(feature = "alloc")]
mod program;
#[cfg(feature = "alloc")]
pub mod report;
#[cfg(feature = "alloc")]
pub mod spin;
#[cfg(feature = "alloc")]
pub mod stock;
#[cfg(feature = "alloc")]
pub mod tools;

#[cfg(feature = "alloc")]
pub use program::{
    ARC_TOLERANCE, AXIS_TOLERANCE, MAX_ARC_TURNS, MAX_AXIS_TURN, MAX_COORDINATE, MAX_DWELL,
    MAX_FEED, MAX_GAP, MAX_MOVES, MAX_SPINDLE_RPM, MAX_TOOL_NUMBER, Motion, Move, Operation,
    PathControl, Plane, Program,
};

pub use kinematics::Kinematics;
