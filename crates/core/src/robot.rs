//! Loading a serial robot from a URDF file (via urdf-rs) and a stiffness TOML file, with the
//! validation urdf-rs leaves to its users.
//!
//! The stiffness file lists virtual joints, applied in file order on each link:
//!
//! ```toml
//! [[virtual_joint]]
//! link = "upper_arm_link"   # URDF link whose frame carries the spring
//! xyz = [0.0, 0.0, 0.2]     # optional, m, spring frame inside that link
//! rpy = [0.0, 0.0, 0.0]     # optional, rad
//! k = [1.5e6, 1.0e6, inf]   # N m / rad about the spring frame's x, y, z
//! ```

use std::collections::{HashMap, HashSet};
use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;

use crate::error::BuildError;
use crate::vjm::{Model, ModelBuilder};

/// A robot description could not be loaded. Every variant names the element at fault.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum LoadError {
    /// A file could not be read.
    Io {
        /// The file.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// urdf-rs rejected the URDF text.
    UrdfParse {
        /// urdf-rs's message.
        message: String,
    },
    /// The stiffness TOML is malformed (syntax, unknown field, wrong type).
    StiffnessParse {
        /// The TOML parser's message, with line and column.
        message: String,
    },
    /// Two links or two joints share a name.
    DuplicateName {
        /// "link" or "joint".
        kind: &'static str,
        /// The repeated name.
        name: String,
    },
    /// A link name that the URDF does not define.
    UnknownLink {
        /// The name.
        link: String,
        /// Where it was used (a joint name, "tip_link", "base_link", "stiffness file").
        referenced_by: String,
    },
    /// The tip link is not a descendant of the base link.
    TipNotReachable {
        /// Requested tip.
        tip: String,
        /// Base link.
        base: String,
    },
    /// The joints form a cycle, or a link has two parent joints.
    NotATree {
        /// The link where the walk from the tip met it.
        link: String,
    },
    /// A joint or virtual-joint origin holds NaN or an infinity.
    NonFiniteOrigin {
        /// The joint (or "virtual_joint #n on link L").
        element: String,
    },
    /// A revolute or prismatic joint axis is zero or not finite.
    ZeroAxis {
        /// The joint.
        joint: String,
    },
    /// A joint limit with `lower > upper` or NaN.
    InvalidLimit {
        /// The joint.
        joint: String,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// A joint type the serial model does not support on the base-to-tip path.
    UnsupportedJoint {
        /// The joint.
        joint: String,
        /// Its type or feature ("floating", "planar", "spherical", "mimic").
        kind: String,
    },
    /// A virtual joint names a link that is not on the base-to-tip chain.
    LinkNotInChain {
        /// The link.
        link: String,
    },
    /// A stiffness is zero, negative or NaN (`inf` = rigid is fine).
    NonPositiveStiffness {
        /// The link of the virtual joint.
        link: String,
        /// Position of the virtual joint in the file, from 0.
        entry: usize,
        /// 0, 1, 2 for x, y, z.
        axis: usize,
        /// The value [N m / rad].
        value: f64,
    },
    /// The real-time model's capacity was exceeded, or another build error.
    Build(BuildError),
}

impl core::fmt::Display for LoadError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Io { path, message } => write!(f, "cannot read {path}: {message}"),
            Self::UrdfParse { message } => write!(f, "invalid URDF: {message}"),
            Self::StiffnessParse { message } => write!(f, "invalid stiffness file: {message}"),
            Self::DuplicateName { kind, name } => write!(f, "duplicate {kind} name '{name}'"),
            Self::UnknownLink {
                link,
                referenced_by,
            } => write!(f, "unknown link '{link}' (referenced by {referenced_by})"),
            Self::TipNotReachable { tip, base } => {
                write!(
                    f,
                    "tip link '{tip}' is not reachable from base link '{base}'"
                )
            }
            Self::NotATree { link } => write!(
                f,
                "the joints around link '{link}' form a cycle or give it two parents"
            ),
            Self::NonFiniteOrigin { element } => {
                write!(f, "{element}: origin is not finite (NaN or inf)")
            }
            Self::ZeroAxis { joint } => write!(f, "joint '{joint}': axis is zero or not finite"),
            Self::InvalidLimit {
                joint,
                lower,
                upper,
            } => write!(
                f,
                "joint '{joint}': invalid limits lower={lower} upper={upper}"
            ),
            Self::UnsupportedJoint { joint, kind } => {
                write!(f, "joint '{joint}': {kind} joints are not supported")
            }
            Self::LinkNotInChain { link } => write!(
                f,
                "virtual joint on link '{link}', which is not on the base-to-tip chain"
            ),
            Self::NonPositiveStiffness {
                link,
                entry,
                axis,
                value,
            } => write!(
                f,
                "virtual_joint #{entry} on link '{link}': stiffness about {} is {value}; it must be > 0 (inf = rigid)",
                ["x", "y", "z"].get(*axis).copied().unwrap_or("?")
            ),
            Self::Build(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for LoadError {}

impl From<BuildError> for LoadError {
    fn from(e: BuildError) -> Self {
        Self::Build(e)
    }
}

/// One `[[virtual_joint]]` entry of the stiffness file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VirtualJointSpec {
    /// URDF link whose frame carries the spring.
    pub link: String,
    /// Spring frame origin in the link frame [m].
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Spring frame orientation in the link frame, URDF roll-pitch-yaw [rad].
    #[serde(default)]
    pub rpy: [f64; 3],
    /// Stiffness about the spring frame's x, y, z [N m / rad]; `inf` = rigid.
    pub k: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StiffnessFile {
    #[serde(default)]
    virtual_joint: Vec<VirtualJointSpec>,
    // Drive-train `[[joint]]` entries may share the file; `crate::drivetrain_io` reads them.
    #[serde(default, rename = "joint")]
    _joint: Option<toml::Value>,
}

/// Parses a stiffness TOML text (format in the module docs). Values are checked when the
/// robot is assembled, where the link names can be resolved.
pub fn parse_stiffness(text: &str) -> Result<Vec<VirtualJointSpec>, LoadError> {
    toml::from_str::<StiffnessFile>(text)
        .map(|f| f.virtual_joint)
        .map_err(|e| LoadError::StiffnessParse {
            message: e.to_string(),
        })
}

/// A serial robot loaded from files: the real-time [`Model`] plus the names that tie it back
/// to the URDF.
#[derive(Debug, Clone)]
pub struct SerialRobot {
    /// The real-time chain.
    pub model: Model,
    /// Actuated joints in `q` order.
    pub joint_names: Vec<String>,
    /// Joint limits `(lower, upper)` [rad or m] in `q` order (infinite where the URDF gives none).
    pub joint_limits: Vec<(f64, f64)>,
    /// One label per virtual joint, in chain order: `"link"` or `"link#n"` for the n-th (from 0)
    /// on the same link.
    pub spring_names: Vec<String>,
    /// The chain's base link.
    pub base_link: String,
    /// The chain's tip (TCP) link.
    pub tip_link: String,
}

fn read(path: &Path) -> Result<String, LoadError> {
    std::fs::read_to_string(path).map_err(|e| LoadError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

fn pose(xyz: &[f64; 3], rpy: &[f64; 3], element: &str) -> Result<Isometry3<f64>, LoadError> {
    if !xyz.iter().chain(rpy.iter()).all(|v| v.is_finite()) {
        return Err(LoadError::NonFiniteOrigin {
            element: element.to_string(),
        });
    }
    // URDF rpy is a fixed-axis x-y-z rotation: R = Rz(yaw) Ry(pitch) Rx(roll).
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    ))
}

impl SerialRobot {
    /// Loads a URDF file and a stiffness TOML file; the chain runs from the URDF's root link
    /// to `tip_link`.
    pub fn from_files(
        urdf_path: impl AsRef<Path>,
        stiffness_path: impl AsRef<Path>,
        tip_link: &str,
    ) -> Result<Self, LoadError> {
        let urdf = read(urdf_path.as_ref())?;
        let stiffness = read(stiffness_path.as_ref())?;
        Self::from_strs(&urdf, &stiffness, None, tip_link)
    }

    /// Loads from URDF and stiffness TOML texts. `base_link` defaults to the URDF's root.
    pub fn from_strs(
        urdf: &str,
        stiffness: &str,
        base_link: Option<&str>,
        tip_link: &str,
    ) -> Result<Self, LoadError> {
        let robot = urdf_rs::read_from_string(urdf).map_err(|e| LoadError::UrdfParse {
            message: e.to_string(),
        })?;
        let springs = parse_stiffness(stiffness)?;
        Self::from_urdf_robot(&robot, &springs, base_link, tip_link)
    }

    /// Assembles the model from a parsed URDF and virtual-joint specs, validating both.
    pub fn from_urdf_robot(
        robot: &urdf_rs::Robot,
        springs: &[VirtualJointSpec],
        base_link: Option<&str>,
        tip_link: &str,
    ) -> Result<Self, LoadError> {
        let mut links = HashSet::new();
        for l in &robot.links {
            if !links.insert(l.name.as_str()) {
                return Err(LoadError::DuplicateName {
                    kind: "link",
                    name: l.name.clone(),
                });
            }
        }
        let mut joint_names = HashSet::new();
        // child link -> joint
        let mut parent_joint: HashMap<&str, &urdf_rs::Joint> = HashMap::new();
        for j in &robot.joints {
            if !joint_names.insert(j.name.as_str()) {
                return Err(LoadError::DuplicateName {
                    kind: "joint",
                    name: j.name.clone(),
                });
            }
            for l in [&j.parent.link, &j.child.link] {
                if !links.contains(l.as_str()) {
                    return Err(LoadError::UnknownLink {
                        link: l.clone(),
                        referenced_by: format!("joint '{}'", j.name),
                    });
                }
            }
            if parent_joint.insert(j.child.link.as_str(), j).is_some() {
                return Err(LoadError::NotATree {
                    link: j.child.link.clone(),
                });
            }
        }
        if !links.contains(tip_link) {
            return Err(LoadError::UnknownLink {
                link: tip_link.to_string(),
                referenced_by: "tip_link".to_string(),
            });
        }
        if let Some(b) = base_link {
            if !links.contains(b) {
                return Err(LoadError::UnknownLink {
                    link: b.to_string(),
                    referenced_by: "base_link".to_string(),
                });
            }
        }
        // Walk from the tip to the base (or the root).
        let mut path: Vec<&urdf_rs::Joint> = Vec::new();
        let mut visited = HashSet::new();
        let mut link = tip_link;
        loop {
            if Some(link) == base_link {
                break;
            }
            if !visited.insert(link) {
                return Err(LoadError::NotATree {
                    link: link.to_string(),
                });
            }
            match parent_joint.get(link) {
                Some(j) => {
                    path.push(j);
                    link = j.parent.link.as_str();
                }
                None => {
                    if let Some(b) = base_link {
                        return Err(LoadError::TipNotReachable {
                            tip: tip_link.to_string(),
                            base: b.to_string(),
                        });
                    }
                    break;
                }
            }
        }
        let base = link.to_string();
        path.reverse();

        // Links on the chain, in order: the base, then each joint's child.
        let chain_links: Vec<&str> = core::iter::once(base.as_str())
            .chain(path.iter().map(|j| j.child.link.as_str()))
            .collect();
        for s in springs {
            if !links.contains(s.link.as_str()) {
                return Err(LoadError::UnknownLink {
                    link: s.link.clone(),
                    referenced_by: "stiffness file".to_string(),
                });
            }
            if !chain_links.contains(&s.link.as_str()) {
                return Err(LoadError::LinkNotInChain {
                    link: s.link.clone(),
                });
            }
        }

        let mut b = ModelBuilder::new();
        let mut names = Vec::new();
        let mut limits = Vec::new();
        let mut spring_names = Vec::new();
        let mut add_springs =
            |mut b: ModelBuilder, link: &str| -> Result<ModelBuilder, LoadError> {
                let mut n_on_link = 0usize;
                for (entry, s) in springs.iter().enumerate() {
                    if s.link != link {
                        continue;
                    }
                    let label = format!("virtual_joint #{entry} on link '{link}'");
                    let frame = pose(&s.xyz, &s.rpy, &label)?;
                    if let Some((axis, &value)) =
                        s.k.iter()
                            .enumerate()
                            .find(|(_, v)| v.is_nan() || **v <= 0.0)
                    {
                        return Err(LoadError::NonPositiveStiffness {
                            link: link.to_string(),
                            entry,
                            axis,
                            value,
                        });
                    }
                    b = b.spring_at(frame, s.k)?;
                    spring_names.push(if n_on_link == 0 {
                        link.to_string()
                    } else {
                        format!("{link}#{n_on_link}")
                    });
                    n_on_link += 1;
                }
                Ok(b)
            };
        b = add_springs(b, &base)?;
        for j in &path {
            if j.mimic.is_some() {
                return Err(LoadError::UnsupportedJoint {
                    joint: j.name.clone(),
                    kind: "mimic".to_string(),
                });
            }
            b = b.fixed(pose(
                &j.origin.xyz.0,
                &j.origin.rpy.0,
                &format!("joint '{}'", j.name),
            )?)?;
            let axis = Vector3::from(j.axis.xyz.0);
            let moving = matches!(
                j.joint_type,
                urdf_rs::JointType::Revolute
                    | urdf_rs::JointType::Continuous
                    | urdf_rs::JointType::Prismatic
            );
            if moving {
                let n = axis.norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(LoadError::ZeroAxis {
                        joint: j.name.clone(),
                    });
                }
                let (lo, hi) = match j.joint_type {
                    urdf_rs::JointType::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
                    _ => (j.limit.lower, j.limit.upper),
                };
                if lo.is_nan() || hi.is_nan() || lo > hi {
                    return Err(LoadError::InvalidLimit {
                        joint: j.name.clone(),
                        lower: lo,
                        upper: hi,
                    });
                }
                b = if j.joint_type == urdf_rs::JointType::Prismatic {
                    b.prismatic(axis)?
                } else {
                    b.revolute(axis)?
                };
                names.push(j.name.clone());
                limits.push((lo, hi));
            } else if j.joint_type != urdf_rs::JointType::Fixed {
                return Err(LoadError::UnsupportedJoint {
                    joint: j.name.clone(),
                    kind: format!("{:?}", j.joint_type).to_lowercase(),
                });
            }
            b = add_springs(b, &j.child.link)?;
        }
        Ok(Self {
            model: b.build()?,
            joint_names: names,
            joint_limits: limits,
            spring_names,
            base_link: base,
            tip_link: tip_link.to_string(),
        })
    }
}
