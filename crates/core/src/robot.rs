//! A serial robot loaded from files: the real-time virtual-joint [`Model`] plus the names that
//! tie it back to its URDF. Loaders: [`crate::io::urdf`] (which also gives
//! `SerialRobot::from_path` and `from_str`) and [`crate::io::stiffness`].

use std::string::String;
use std::vec::Vec;

use crate::vjm::Model;

/// A serial robot loaded from files: the real-time [`Model`] plus the names that tie it back
/// to the URDF.
#[derive(Debug, Clone)]
pub struct SerialRobot {
    /// The real-time chain.
    pub model: Model,
    /// Actuated joints in `q` order.
    pub joint_names: Vec<String>,
    /// Joint limits `(lower, upper)` \[rad or m\] in `q` order (infinite where the URDF gives none).
    pub joint_limits: Vec<(f64, f64)>,
    /// One label per virtual joint, in chain order: `"link"` or `"link#n"` for the n-th (from 0)
    /// on the same link.
    pub spring_names: Vec<String>,
    /// The chain's base link.
    pub base_link: String,
    /// The chain's tip (TCP) link.
    pub tip_link: String,
    /// How its controller reads the joints and frames (the `[controller]` table of the
    /// stiffness file, [`crate::io::controller`]); `None` without one: no robot program but
    /// CSV can be written for it.
    pub controller: Option<crate::controller::Convention>,
}
