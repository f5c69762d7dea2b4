//! The drive-train [`Model`] of a [`SerialRobot`]: per-joint stiffness and backlash from a
//! TOML file, link masses and centres of mass from the URDF `<inertial>` elements.
//!
//! The drive-train entries may sit in the robot's stiffness file next to its virtual joints
//! (the VJM loader skips them) or in a file of their own:
//!
//! ```toml
//! [[joint]]
//! name = "a1"          # URDF name of an actuated joint on the chain
//! stiffness = 1.0e5    # K_i: N m/rad (N/m for a prismatic joint), finite and > 0
//! backlash = 1.0e-4    # theta_b_i: rad (m for a prismatic joint), >= 0; optional, default 0
//! ```
//!
//! Every actuated joint of the chain needs exactly one entry. Masses: each chain link's
//! `<inertial>` mass \[kg\] at its `<origin xyz>` \[m\] (the centre of mass in the link frame)
//! hangs after the last actuated joint before that link; links before the first actuated
//! joint load no joint and are skipped, and so are links off the base-to-tip chain (branches
//! such as grippers or sensors on other links: add them with [`crate::drivetrain::LinkMasses::push`]). Masses
//! after the same joint are merged into one point mass (exact for gravity), so any URDF fits
//! the fixed table.

use std::collections::HashMap;
use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::{Isometry3, Vector3};
use serde::Deserialize;

use crate::drivetrain::{LinkMasses, Model};
use crate::error::LoadError;
use crate::robot::SerialRobot;
use crate::vjm::MAX_DOF;

/// One `[[joint]]` entry of a drive-train file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDriveSpec {
    /// URDF name of the actuated joint.
    pub name: String,
    /// Joint stiffness `K_i` \[N m/rad, or N/m for a prismatic joint\].
    pub stiffness: f64,
    /// Backlash `theta_b_i` \[rad, or m for a prismatic joint\].
    #[serde(default)]
    pub backlash: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DriveFile {
    #[serde(default)]
    joint: Vec<JointDriveSpec>,
    // Tolerated so that the drive train can share the VJM stiffness file.
    #[serde(default, rename = "virtual_joint")]
    _virtual_joint: Option<toml::Value>,
    #[serde(default, rename = "controller")]
    _controller: Option<toml::Value>,
}

/// Parses the `[[joint]]` entries of a drive-train (or combined stiffness) TOML text.
pub fn parse(text: &str) -> Result<Vec<JointDriveSpec>, LoadError> {
    super::check_size("drive-train file", text)?;
    toml::from_str::<DriveFile>(text)
        .map(|f| f.joint)
        .map_err(|e| LoadError::StiffnessParse {
            message: e.to_string(),
        })
}

/// The link masses of `serial`'s base-to-tip chain from the parsed URDF it was loaded from
/// (rules in the module docs).
pub fn link_masses(robot: &urdf_rs::Robot, serial: &SerialRobot) -> Result<LinkMasses, LoadError> {
    let parent_joint: HashMap<&str, &urdf_rs::Joint> = robot
        .joints
        .iter()
        .map(|j| (j.child.link.as_str(), j))
        .collect();
    let links: HashMap<&str, &urdf_rs::Link> =
        robot.links.iter().map(|l| (l.name.as_str(), l)).collect();
    let mut path = Vec::new();
    let mut link = serial.tip_link.as_str();
    while link != serial.base_link {
        let Some(j) = parent_joint.get(link) else {
            return Err(LoadError::TipNotReachable {
                tip: serial.tip_link.clone(),
                base: serial.base_link.clone(),
            });
        };
        if path.len() > robot.joints.len() {
            return Err(LoadError::NotATree {
                link: link.to_string(),
            });
        }
        path.push(*j);
        link = j.parent.link.as_str();
    }
    path.reverse();
    let mut mass = [0.0f64; MAX_DOF];
    let mut moment = [Vector3::<f64>::zeros(); MAX_DOF];
    let mut current: Option<usize> = None;
    let mut offset = Isometry3::identity();
    let mut n_moving = 0usize;
    for j in &path {
        let moving = matches!(
            j.joint_type,
            urdf_rs::JointType::Revolute
                | urdf_rs::JointType::Continuous
                | urdf_rs::JointType::Prismatic
        );
        if moving {
            if serial.joint_names.get(n_moving) != Some(&j.name) {
                return Err(LoadError::UnknownJoint {
                    joint: j.name.clone(),
                    referenced_by: "the URDF chain (not the robot's joint list)".to_string(),
                });
            }
            current = Some(n_moving);
            n_moving += 1;
            offset = Isometry3::identity();
        } else {
            offset *= super::origin::pose(
                &j.origin.xyz.0,
                &j.origin.rpy.0,
                &format!("joint '{}'", j.name),
            )?;
        }
        let (Some(index), Some(l)) = (current, links.get(j.child.link.as_str())) else {
            continue;
        };
        let m = l.inertial.mass.value;
        if !(m.is_finite() && m >= 0.0) {
            return Err(LoadError::InvalidValue {
                element: format!("link '{}' inertial", l.name),
                field: "mass",
                expected: "finite and >= 0 (kg)".to_string(),
                got: m.to_string(),
            });
        }
        let com_local = Vector3::from(l.inertial.origin.xyz.0);
        if !com_local.iter().all(|v| v.is_finite()) {
            return Err(LoadError::NonFiniteOrigin {
                element: format!("inertial of link '{}'", l.name),
            });
        }
        let com = offset.transform_point(&com_local.into()).coords;
        if let (Some(ms), Some(mo)) = (mass.get_mut(index), moment.get_mut(index)) {
            *ms += m;
            *mo += com * m;
        }
    }
    let mut out = LinkMasses::new();
    for (index, (&m, s)) in mass.iter().zip(moment.iter()).enumerate().take(n_moving) {
        if m > 0.0 {
            out.push(index, m, s / m).map_err(LoadError::Build)?;
        }
    }
    Ok(out)
}

/// Builds the drive train of `serial` from its URDF text (masses) and the `[[joint]]`
/// entries of `drive_toml` (stiffness, backlash).
pub fn from_str(serial: &SerialRobot, urdf: &str, drive_toml: &str) -> Result<Model, LoadError> {
    let robot = super::urdf::parse(urdf)?;
    let specs = parse(drive_toml)?;
    let n = serial.joint_names.len();
    let mut stiffness: Vec<Option<f64>> = std::vec![None; n];
    let mut backlash = std::vec![0.0; n];
    for (entry, s) in specs.iter().enumerate() {
        let Some(i) = serial.joint_names.iter().position(|name| *name == s.name) else {
            return Err(LoadError::UnknownJoint {
                joint: s.name.clone(),
                referenced_by: format!(
                    "[[joint]] #{entry} (actuated joints: {})",
                    serial.joint_names.join(", ")
                ),
            });
        };
        let element = || format!("[[joint]] '{}'", s.name);
        if !(s.stiffness.is_normal() && s.stiffness > 0.0) {
            return Err(LoadError::InvalidValue {
                element: element(),
                field: "stiffness",
                expected: "a normal number > 0 (N m/rad)".to_string(),
                got: s.stiffness.to_string(),
            });
        }
        if !(s.backlash.is_finite() && s.backlash >= 0.0) {
            return Err(LoadError::InvalidValue {
                element: element(),
                field: "backlash",
                expected: "finite and >= 0 (rad)".to_string(),
                got: s.backlash.to_string(),
            });
        }
        match stiffness.get_mut(i) {
            Some(slot @ None) => *slot = Some(s.stiffness),
            _ => {
                return Err(LoadError::DuplicateName {
                    kind: "[[joint]] entry",
                    name: s.name.clone(),
                });
            }
        }
        if let Some(b) = backlash.get_mut(i) {
            *b = s.backlash;
        }
    }
    let mut k = Vec::with_capacity(n);
    for (name, s) in serial.joint_names.iter().zip(stiffness.iter()) {
        match s {
            Some(v) => k.push(*v),
            None => {
                return Err(LoadError::InvalidValue {
                    element: format!("joint '{name}'"),
                    field: "[[joint]] entry",
                    expected: "one entry per actuated joint".to_string(),
                    got: "none".to_string(),
                });
            }
        }
    }
    let masses = link_masses(&robot, serial)?;
    Ok(Model::new(serial.model.clone(), &k, &backlash)?.with_masses(masses)?)
}

/// [`from_str`] on the texts of the URDF file and the drive-train file.
pub fn from_path(
    serial: &SerialRobot,
    urdf_path: impl AsRef<Path>,
    drive_path: impl AsRef<Path>,
) -> Result<Model, LoadError> {
    from_str(
        serial,
        &super::read_text(urdf_path.as_ref())?,
        &super::read_text(drive_path.as_ref())?,
    )
}
