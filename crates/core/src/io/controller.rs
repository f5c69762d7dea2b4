//! The `[controller]` table of a robot's stiffness TOML file: how its controller reads the
//! URDF's joints and frames ([`crate::controller::Convention`]). The robot programs of
//! [`super::robot_program`] need it; a robot without one writes CSV only.
//!
//! ```toml
//! [controller]
//! vendor = "kuka"                       # "kuka" (KRL), "abb" (RAPID), "ur" (URScript)
//! joint_sign = [-1, 1, 1, -1, 1, -1]    # per joint in chain order: +1 turns with the URDF axis
//! joint_offset = [0, 0, 0, 0, 0, 0]     # the controller's value at URDF 0, rad (m: prismatic)
//! flange = "ft_sensor"                  # the link carrying the controller's flange frame
//! flange_xyz = [0, 0, 0]                # optional, m, in that link's frame
//! flange_rpy = [0, 0, 0]                # optional, rad
//! base_xyz = [0, 0, 0]                  # optional: the controller's base frame (KUKA
//! base_rpy = [0, 0, 0]                  #   $ROBROOT, ABB base) in the chain's base link, m, rad
//! ```
//!
//! `controller = sign * URDF + offset`, so `offset` is the controller's reading where the
//! URDF's joint is 0 (ABB's axis 2 reads 0 upright; a URDF drawn with the lower arm forward
//! at 0 has `offset = pi / 2` there). The flange link must lie past the chain's last actuated
//! joint (only fixed joints between it and the tip): the TCP in the flange frame follows from
//! the URDF and becomes the program's tool frame.

use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::Isometry3;
use serde::Deserialize;

use super::origin::pose;
use crate::controller::{Convention, Vendor};
use crate::error::LoadError;
use crate::robot::SerialRobot;

/// The `[controller]` table as written (see the module docs).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// `"kuka"`, `"abb"` or `"ur"`.
    pub vendor: String,
    /// +1 or -1 per joint, chain order.
    pub joint_sign: Vec<f64>,
    /// The controller's value at the URDF's 0 per joint \[rad or m\]; default 0.
    #[serde(default)]
    pub joint_offset: Option<Vec<f64>>,
    /// The link whose frame (moved by `flange_xyz`, `flange_rpy`) is the controller's flange.
    pub flange: String,
    /// \[m\], default 0.
    #[serde(default)]
    pub flange_xyz: Option<[f64; 3]>,
    /// \[rad\], URDF roll-pitch-yaw, default 0.
    #[serde(default)]
    pub flange_rpy: Option<[f64; 3]>,
    /// The controller's base frame in the chain's base link \[m\], default 0.
    #[serde(default)]
    pub base_xyz: Option<[f64; 3]>,
    /// \[rad\], default 0.
    #[serde(default)]
    pub base_rpy: Option<[f64; 3]>,
}

#[derive(Debug, Deserialize)]
struct File {
    #[serde(default)]
    controller: Option<ControllerSpec>,
    // The springs and the drive train share the file; they are read by their own loaders.
    #[serde(flatten)]
    _rest: toml::Table,
}

/// The `[controller]` table of a stiffness TOML text, `None` without one.
pub fn from_str(text: &str) -> Result<Option<ControllerSpec>, LoadError> {
    super::check_size("stiffness file", text)?;
    toml::from_str::<File>(text)
        .map(|f| f.controller)
        .map_err(|e| LoadError::StiffnessParse {
            message: e.to_string(),
        })
}

/// The TCP in `link`'s frame: the fixed joints from `link` to the tip; an error naming the
/// flange when an actuated joint lies between (or the link is not on the chain).
fn tip_in(robot: &urdf_rs::Robot, link: &str, tip: &str) -> Result<Isometry3<f64>, LoadError> {
    let bad = |expected: &str| LoadError::InvalidValue {
        element: "[controller]".to_string(),
        field: "flange",
        expected: expected.to_string(),
        got: format!("'{link}'"),
    };
    let mut t = Isometry3::identity();
    let mut at = tip;
    for _ in 0..=robot.joints.len() {
        if at == link {
            return Ok(t);
        }
        let Some(j) = robot.joints.iter().find(|j| j.child.link == at) else {
            break;
        };
        if j.joint_type != urdf_rs::JointType::Fixed {
            return Err(bad(&format!(
                "a link past the chain's last actuated joint ('{}' moves between it and the tip)",
                j.name
            )));
        }
        let o = pose(
            &j.origin.xyz.0,
            &j.origin.rpy.0,
            &format!("joint '{}'", j.name),
        )?;
        t = o * t;
        at = j.parent.link.as_str();
    }
    Err(bad(
        "a link of the chain between its last actuated joint and the tip",
    ))
}

/// The convention of `spec` for `serial` (loaded from `robot` with tip `tip`).
pub fn convention(
    spec: &ControllerSpec,
    robot: &urdf_rs::Robot,
    serial: &SerialRobot,
) -> Result<Convention, LoadError> {
    let element = "[controller]".to_string();
    let vendor = Vendor::from_name(&spec.vendor).ok_or_else(|| LoadError::InvalidValue {
        element: element.clone(),
        field: "vendor",
        expected: "\"kuka\", \"abb\" or \"ur\"".to_string(),
        got: format!("{:?}", spec.vendor),
    })?;
    let zero = [0.0; 3];
    let flange = pose(
        spec.flange_xyz.as_ref().unwrap_or(&zero),
        spec.flange_rpy.as_ref().unwrap_or(&zero),
        "[controller] flange",
    )?;
    let base = pose(
        spec.base_xyz.as_ref().unwrap_or(&zero),
        spec.base_rpy.as_ref().unwrap_or(&zero),
        "[controller] base",
    )?;
    let tool = flange.inverse() * tip_in(robot, &spec.flange, &serial.tip_link)?;
    let offsets = spec
        .joint_offset
        .clone()
        .unwrap_or_else(|| std::vec![0.0; spec.joint_sign.len()]);
    Convention::new(
        vendor,
        &serial.model,
        &spec.joint_sign,
        &offsets,
        base,
        tool,
    )
    .map_err(|e| LoadError::InvalidValue {
        element,
        field: "joint_sign / joint_offset",
        expected: format!(
            "one per joint of the chain ({}): {e}",
            serial.joint_names.join(", ")
        ),
        got: format!("{:?} / {:?}", spec.joint_sign, spec.joint_offset),
    })
}
