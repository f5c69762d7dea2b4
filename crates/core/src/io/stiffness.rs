//! The stiffness TOML file of a serial robot: its virtual joints, applied in file order on
//! each link. A spring is placed either at a joint or inside a link (exactly one of the two):
//!
//! ```toml
//! # At a joint: the spring frame is the joint's frame (the URDF frame of its child link, at
//! # the joint origin, turning with the joint), rotated so that its FIRST axis (x) is the
//! # joint axis: k[0] is the torsional stiffness of the drive, k[1] and k[2] its bending
//! # stiffnesses about two axes normal to it. The rotation is the shortest one from x to the
//! # joint axis (a half turn about z when the axis is -x), so y and z are defined.
//! [[virtual_joint]]
//! joint = "shoulder_lift_joint"  # revolute, continuous or prismatic joint on the chain
//! k = [4.0e4, 2.0e5, 2.0e5]      # N m / rad about the joint axis, then the two normals
//!
//! # Inside a link: any frame given in the link's URDF frame.
//! [[virtual_joint]]
//! link = "upper_arm_link"   # URDF link whose frame carries the spring
//! xyz = [0.0, 0.0, 0.2]     # optional, m, spring frame inside that link
//! rpy = [0.0, 0.0, 0.0]     # optional, rad
//! k = [1.5e6, 1.0e6, inf]   # N m / rad about the spring frame's x, y, z
//! ```
//!
//! `inf` makes an axis rigid; every other value must be a normal number > 0. Drive-train
//! `[[joint]]` entries may share the file ([`super::drive`] reads them).

use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use serde::{Deserialize, Deserializer};

use crate::error::LoadError;

/// Reads exactly three numbers (TOML would otherwise truncate a longer array silently).
fn three<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    <[f64; 3]>::try_from(v.as_slice()).map_err(|_| {
        serde::de::Error::custom(std::format!("expected 3 values (x, y, z), got {}", v.len()))
    })
}

/// Reads exactly three numbers, when present.
fn three_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 3]>, D::Error> {
    three(d).map(Some)
}

/// One `[[virtual_joint]]` entry of the stiffness file: at a `joint`, or inside a `link` at
/// `xyz`/`rpy` (exactly one of `joint` and `link`; `xyz`/`rpy` only with `link`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VirtualJointSpec {
    /// URDF link whose frame carries the spring.
    #[serde(default)]
    pub link: Option<String>,
    /// URDF joint at whose frame the spring sits, its first axis along the joint axis.
    #[serde(default)]
    pub joint: Option<String>,
    /// Spring frame origin in the link frame \[m\] (with `link` only; default 0).
    #[serde(default, deserialize_with = "three_opt")]
    pub xyz: Option<[f64; 3]>,
    /// Spring frame orientation in the link frame, URDF roll-pitch-yaw \[rad\] (with `link`
    /// only; default 0).
    #[serde(default, deserialize_with = "three_opt")]
    pub rpy: Option<[f64; 3]>,
    /// Stiffness about the spring frame's x, y, z \[N m / rad\]; `inf` = rigid.
    #[serde(deserialize_with = "three")]
    pub k: [f64; 3],
}

impl VirtualJointSpec {
    /// A spring inside `link` at `xyz` \[m\], `rpy` \[rad\].
    pub fn at_link(link: &str, xyz: [f64; 3], rpy: [f64; 3], k: [f64; 3]) -> Self {
        Self {
            link: Some(link.to_string()),
            joint: None,
            xyz: Some(xyz),
            rpy: Some(rpy),
            k,
        }
    }

    /// A spring at `joint`, first axis along the joint axis.
    pub fn at_joint(joint: &str, k: [f64; 3]) -> Self {
        Self {
            link: None,
            joint: Some(joint.to_string()),
            xyz: None,
            rpy: None,
            k,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StiffnessFile {
    #[serde(default)]
    virtual_joint: Vec<VirtualJointSpec>,
    // Drive-train `[[joint]]` entries may share the file; `crate::drivetrain_io` reads them.
    #[serde(default, rename = "joint")]
    _joint: Option<toml::Value>,
    // The controller's convention shares it too ([`super::controller`] reads it).
    #[serde(default, rename = "controller")]
    _controller: Option<toml::Value>,
}

/// Parses a stiffness TOML text (format in the module docs). Values are checked when the
/// robot is assembled, where the link names can be resolved. A file without any
/// `[[virtual_joint]]` entry is refused: the robot would be rigid, and an empty or wrong
/// file must not pass for one.
pub fn from_str(text: &str) -> Result<Vec<VirtualJointSpec>, LoadError> {
    super::check_size("stiffness file", text)?;
    let specs = toml::from_str::<StiffnessFile>(text)
        .map(|f| f.virtual_joint)
        .map_err(|e| LoadError::StiffnessParse {
            message: e.to_string(),
        })?;
    if specs.is_empty() {
        return Err(LoadError::StiffnessParse {
            message: "no [[virtual_joint]] entries: the robot would be rigid".to_string(),
        });
    }
    for (entry, s) in specs.iter().enumerate() {
        let placed = match (&s.link, &s.joint) {
            (Some(_), None) => None,
            (None, Some(_)) if s.xyz.is_none() && s.rpy.is_none() => None,
            (None, Some(_)) => Some("`xyz`/`rpy` only with `link` (a joint fixes the frame)"),
            (Some(_), Some(_)) => Some("exactly one of `link` and `joint`, not both"),
            (None, None) => Some("exactly one of `link` and `joint`"),
        };
        if let Some(expected) = placed {
            return Err(LoadError::InvalidValue {
                element: std::format!("virtual_joint #{entry}"),
                field: "placement",
                expected: expected.to_string(),
                got: std::format!(
                    "link = {:?}, joint = {:?}, xyz = {:?}, rpy = {:?}",
                    s.link,
                    s.joint,
                    s.xyz,
                    s.rpy
                ),
            });
        }
    }
    Ok(specs)
}

/// [`from_str`] on the text of the file at `path`.
pub fn from_path(path: impl AsRef<Path>) -> Result<Vec<VirtualJointSpec>, LoadError> {
    from_str(&super::read_text(path.as_ref())?)
}
