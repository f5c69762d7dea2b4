//! A serial robot loaded from files: the real-time virtual-joint [`Model`] plus the names that
//! tie it back to its URDF. Loaders: [`crate::io::urdf`] and [`crate::io::stiffness`].

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
}

#[cfg(feature = "urdf")]
impl SerialRobot {
    /// Loads a URDF file and a stiffness TOML file; the chain runs from the URDF's root link
    /// to `tip_link` ([`crate::io::urdf::from_path`] also takes a base link).
    ///
    /// ```
    /// use deflect_core::SerialRobot;
    /// use deflect_core::vjm::{self, Data, Vector6};
    /// let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/kr300/");
    /// let robot = SerialRobot::from_path(
    ///     format!("{dir}kr300_r2500.urdf"), format!("{dir}kr300_r2500_stiffness.toml"), "tcp")?;
    /// let mut data = Data::new(&robot.model);
    /// let q = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
    /// // 750 N along +x at the TCP pushes it about 1.7 mm along x.
    /// let w = Vector6::new(750.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    /// let d = vjm::deflection(&robot.model, &mut data, &q, &w, vjm::Load::Exact)?;
    /// assert!((d.x - 1.693e-3).abs() < 1e-5);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_path(
        urdf_path: impl AsRef<std::path::Path>,
        stiffness_path: impl AsRef<std::path::Path>,
        tip_link: &str,
    ) -> Result<Self, crate::LoadError> {
        crate::io::urdf::from_path(urdf_path, stiffness_path, None, tip_link)
    }

    /// Loads from URDF and stiffness TOML texts; `base_link` defaults to the URDF's root.
    /// See [`crate::io::urdf::from_str`].
    pub fn from_str(
        urdf: &str,
        stiffness: &str,
        base_link: Option<&str>,
        tip_link: &str,
    ) -> Result<Self, crate::LoadError> {
        crate::io::urdf::from_str(urdf, stiffness, base_link, tip_link)
    }
}
