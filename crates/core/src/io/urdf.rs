//! Serial robots from a URDF (via urdf-rs) and a stiffness TOML file, with the validation
//! urdf-rs leaves to its users (non-finite origins, zero axes, duplicate names, missing
//! links, cycles, inverted limits, unsupported joints).

use std::collections::{HashMap, HashSet};
use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::stiffness::VirtualJointSpec;
use crate::error::LoadError;
use crate::robot::SerialRobot;
use crate::vjm::ModelBuilder;

impl SerialRobot {
    /// Loads a URDF file and a stiffness TOML file; the chain runs from the URDF's root link
    /// to `tip_link` ([`from_path`] also takes a base link).
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
        from_path(urdf_path, stiffness_path, None, tip_link)
    }

    /// Loads from URDF and stiffness TOML texts; `base_link` defaults to the URDF's root.
    /// See [`from_str`].
    pub fn from_str(
        urdf: &str,
        stiffness: &str,
        base_link: Option<&str>,
        tip_link: &str,
    ) -> Result<Self, crate::LoadError> {
        from_str(urdf, stiffness, base_link, tip_link)
    }
}

pub use super::origin::MAX_ORIGIN;
use super::origin::pose;

/// Appends the `<inertial>` of `link` (if it has mass or inertia) as a link mass: centre of
/// mass at the inertial origin, inertia rotated from the inertial frame to the link frame.
/// The mass loads the springs under motion only ([`crate::vjm::Load::ExactWithArm`]).
fn link_mass(b: ModelBuilder, link: &urdf_rs::Link) -> Result<ModelBuilder, LoadError> {
    let i = &link.inertial;
    let m = &i.inertia;
    let tensor = nalgebra::Matrix3::new(
        m.ixx, m.ixy, m.ixz, m.ixy, m.iyy, m.iyz, m.ixz, m.iyz, m.izz,
    );
    if i.mass.value == 0.0 && tensor.iter().all(|v| *v == 0.0) {
        return Ok(b);
    }
    let element = format!("link '{}' <inertial>", link.name);
    let bad = |field: &'static str, expected: &str, got: String| LoadError::InvalidValue {
        element: element.clone(),
        field,
        expected: expected.to_string(),
        got,
    };
    if !(i.mass.value.is_finite() && i.mass.value >= 0.0) {
        return Err(bad(
            "mass",
            "finite and >= 0 (kg)",
            i.mass.value.to_string(),
        ));
    }
    let frame = pose(&i.origin.xyz.0, &i.origin.rpy.0, &element)?;
    let r = frame.rotation.to_rotation_matrix();
    let inertia = r.matrix() * tensor * r.matrix().transpose();
    b.mass(i.mass.value, frame.translation.vector, inertia)
        .map_err(|e| {
            bad(
                "inertia",
                "finite, symmetric, positive semi-definite (kg m^2)",
                e.to_string(),
            )
        })
}

/// The frame of a spring placed at a joint, in the joint's (child link's) frame: the shortest
/// rotation taking x onto the unit joint `axis` (a half turn about z for `axis = -x`).
pub fn joint_spring_frame(axis: &Vector3<f64>) -> Isometry3<f64> {
    let rotation = UnitQuaternion::rotation_between(&Vector3::x(), axis).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), core::f64::consts::PI)
    });
    Isometry3::from_parts(Translation3::identity(), rotation)
}

/// Most nested XML elements a URDF may have (a URDF nests 4-5 deep). urdf-rs converts
/// elements recursively, so a deeper file would overflow the stack; it is refused first.
pub const MAX_XML_DEPTH: usize = 64;

/// Parses a URDF text with urdf-rs, after checking what urdf-rs does not: the size budget,
/// the nesting depth ([`MAX_XML_DEPTH`]) and a single `<robot>` root element.
pub fn parse(urdf: &str) -> Result<urdf_rs::Robot, LoadError> {
    super::check_size("URDF", urdf)?;
    super::xml::check_structure(urdf, "robot", MAX_XML_DEPTH)?;
    urdf_rs::read_from_string(urdf).map_err(|e| LoadError::UrdfParse {
        message: e.to_string(),
    })
}

/// Loads a serial robot from URDF and stiffness TOML texts. The chain runs from `base_link`
/// (default: the URDF's root) to `tip_link`. The URDF must be one tree (a second root link
/// is refused, naming the roots). A joint axis of any non-zero length is normalised (the
/// specification asks for a unit vector; exporters round): `0 0 2` is the z axis, and a
/// prismatic joint still moves one metre per unit of `q`.
pub fn from_str(
    urdf: &str,
    stiffness: &str,
    base_link: Option<&str>,
    tip_link: &str,
) -> Result<SerialRobot, LoadError> {
    let robot = parse(urdf)?;
    let springs = super::stiffness::from_str(stiffness)?;
    let mut serial = assemble(&robot, &springs, base_link, tip_link)?;
    if let Some(spec) = super::controller::from_str(stiffness)? {
        serial.controller = Some(super::controller::convention(&spec, &robot, &serial)?);
    }
    Ok(serial)
}

/// [`from_str`] on the texts of the URDF file and the stiffness file.
pub fn from_path(
    urdf_path: impl AsRef<Path>,
    stiffness_path: impl AsRef<Path>,
    base_link: Option<&str>,
    tip_link: &str,
) -> Result<SerialRobot, LoadError> {
    let urdf = super::read_text(urdf_path.as_ref())?;
    let stiffness = super::read_text(stiffness_path.as_ref())?;
    from_str(&urdf, &stiffness, base_link, tip_link)
}

/// Child link -> its joint, with the set of link names and the set of joint names.
type TreeIndex<'a> = (
    HashSet<&'a str>,
    HashSet<&'a str>,
    HashMap<&'a str, &'a urdf_rs::Joint>,
);

/// A virtual joint resolved to (link, frame in the link, label).
type Placed = (String, Isometry3<f64>, String);

/// Assembles a serial robot from a parsed URDF and virtual-joint specs, validating both.
pub fn assemble(
    robot: &urdf_rs::Robot,
    springs: &[VirtualJointSpec],
    base_link: Option<&str>,
    tip_link: &str,
) -> Result<SerialRobot, LoadError> {
    let (links, joint_names, parent_joint) = index_tree(robot)?;
    check_single_root(robot, &parent_joint)?;
    check_chain_ends(&links, base_link, tip_link)?;
    let (base, path) = chain_path(&parent_joint, base_link, tip_link)?;
    let base = base.to_string();

    // Links on the chain, in order: the base, then each joint's child.
    let chain_links: Vec<&str> = core::iter::once(base.as_str())
        .chain(path.iter().map(|j| j.child.link.as_str()))
        .collect();
    let placed = place_springs(springs, &links, &joint_names, &chain_links, &path)?;

    let mut b = ModelBuilder::new();
    let mut names = Vec::new();
    let mut limits = Vec::new();
    let mut spring_names = Vec::new();
    b = add_link_springs(b, robot, &placed, springs, &mut spring_names, &base)?;
    for j in &path {
        b = add_chain_joint(b, j, &mut names, &mut limits)?;
        b = add_link_springs(b, robot, &placed, springs, &mut spring_names, &j.child.link)?;
    }
    Ok(SerialRobot {
        model: b.build()?,
        joint_names: names,
        joint_limits: limits,
        spring_names,
        base_link: base,
        tip_link: tip_link.to_string(),
        controller: None,
    })
}

/// Indexes the URDF tree (link names, joint names, child link -> joint), refusing
/// duplicate names, joints naming unknown links and links with two parents.
fn index_tree(robot: &urdf_rs::Robot) -> Result<TreeIndex<'_>, LoadError> {
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
    Ok((links, joint_names, parent_joint))
}

/// Refuses a URDF with more than one root link, naming (up to 8 of) them.
fn check_single_root(
    robot: &urdf_rs::Robot,
    parent_joint: &HashMap<&str, &urdf_rs::Joint>,
) -> Result<(), LoadError> {
    // The URDF specification asks for one tree: a second root is a link nothing attaches,
    // left over or misspelt, and which of them is the base would be a guess.
    let mut roots: Vec<&str> = robot
        .links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|l| !parent_joint.contains_key(l))
        .collect();
    if roots.len() > 1 {
        roots.truncate(8);
        return Err(LoadError::InvalidValue {
            element: "URDF".to_string(),
            field: "root links",
            expected: "one root link (every other link the child of a joint)".to_string(),
            got: format!(
                "several: '{}'{}",
                roots.join("', '"),
                if roots.len() == 8 { ", ..." } else { "" }
            ),
        });
    }
    Ok(())
}

/// Refuses a tip link (or base link) the URDF does not have.
fn check_chain_ends(
    links: &HashSet<&str>,
    base_link: Option<&str>,
    tip_link: &str,
) -> Result<(), LoadError> {
    if !links.contains(tip_link) {
        return Err(LoadError::UnknownLink {
            link: tip_link.to_string(),
            referenced_by: "tip_link".to_string(),
        });
    }
    if let Some(b) = base_link
        && !links.contains(b)
    {
        return Err(LoadError::UnknownLink {
            link: b.to_string(),
            referenced_by: "base_link".to_string(),
        });
    }
    Ok(())
}

/// The chain's base link and its joints from base to tip, walked from the tip up to
/// `base_link` (or the root), refusing cycles and a base the tip does not hang from.
fn chain_path<'a>(
    parent_joint: &HashMap<&'a str, &'a urdf_rs::Joint>,
    base_link: Option<&str>,
    tip_link: &'a str,
) -> Result<(&'a str, Vec<&'a urdf_rs::Joint>), LoadError> {
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
    path.reverse();
    Ok((link, path))
}

/// Resolves every virtual joint of the stiffness file to (link, frame in the link, label),
/// in file order.
fn place_springs(
    springs: &[VirtualJointSpec],
    links: &HashSet<&str>,
    joint_names: &HashSet<&str>,
    chain_links: &[&str],
    path: &[&urdf_rs::Joint],
) -> Result<Vec<Placed>, LoadError> {
    let mut placed: Vec<Placed> = Vec::with_capacity(springs.len());
    for (entry, s) in springs.iter().enumerate() {
        let (link, frame, label) = match (&s.link, &s.joint) {
            (Some(link), _) => {
                if !links.contains(link.as_str()) {
                    return Err(LoadError::UnknownLink {
                        link: link.clone(),
                        referenced_by: format!("virtual_joint #{entry} of the stiffness file"),
                    });
                }
                if !chain_links.contains(&link.as_str()) {
                    return Err(LoadError::LinkNotInChain { link: link.clone() });
                }
                let label = format!("virtual_joint #{entry} on link '{link}'");
                let frame = pose(
                    &s.xyz.unwrap_or([0.0; 3]),
                    &s.rpy.unwrap_or([0.0; 3]),
                    &label,
                )?;
                (link.clone(), frame, label)
            }
            (None, Some(joint)) => place_at_joint(entry, joint, joint_names, path)?,
            (None, None) => {
                return Err(LoadError::InvalidValue {
                    element: format!("virtual_joint #{entry}"),
                    field: "placement",
                    expected: "exactly one of `link` and `joint`".to_string(),
                    got: "neither".to_string(),
                });
            }
        };
        placed.push((link, frame, label));
    }
    Ok(placed)
}

/// Resolves virtual joint #`entry`, placed at `joint`, to its child link and the frame
/// along the joint's axis; the joint must be a moving one on the chain.
fn place_at_joint(
    entry: usize,
    joint: &String,
    joint_names: &HashSet<&str>,
    path: &[&urdf_rs::Joint],
) -> Result<Placed, LoadError> {
    let label = format!("virtual_joint #{entry} at joint '{joint}'");
    let Some(j) = path.iter().find(|j| j.name == *joint) else {
        return Err(LoadError::UnknownJoint {
            joint: joint.clone(),
            referenced_by: if joint_names.contains(joint.as_str()) {
                format!("{label} (the joint is not on the base-to-tip chain)")
            } else {
                label
            },
        });
    };
    if !matches!(
        j.joint_type,
        urdf_rs::JointType::Revolute
            | urdf_rs::JointType::Continuous
            | urdf_rs::JointType::Prismatic
    ) {
        return Err(LoadError::UnsupportedJoint {
            joint: joint.clone(),
            kind: format!(
                "{} (a spring at a joint needs a moving joint's axis)",
                format!("{:?}", j.joint_type).to_lowercase()
            ),
        });
    }
    let axis = Vector3::from(j.axis.xyz.0);
    let n = axis.norm();
    if !(n.is_finite() && n > 0.0) {
        return Err(LoadError::ZeroAxis {
            joint: joint.clone(),
        });
    }
    Ok((j.child.link.clone(), joint_spring_frame(&(axis / n)), label))
}

/// Adds the springs placed on `link` (in file order, naming each) and then the link's mass.
fn add_link_springs(
    mut b: ModelBuilder,
    robot: &urdf_rs::Robot,
    placed: &[Placed],
    springs: &[VirtualJointSpec],
    spring_names: &mut Vec<String>,
    link: &str,
) -> Result<ModelBuilder, LoadError> {
    let mut n_on_link = 0usize;
    for ((on, frame, label), s) in placed.iter().zip(springs) {
        if on != link {
            continue;
        }
        if let Some((axis, &value)) =
            s.k.iter()
                .enumerate()
                .find(|(_, v)| !crate::vjm::valid_stiffness(**v))
        {
            return Err(LoadError::NonPositiveStiffness {
                element: label.clone(),
                axis,
                value,
            });
        }
        b = b.spring_at(*frame, s.k)?;
        spring_names.push(match &s.joint {
            Some(joint) => joint.clone(),
            None if n_on_link == 0 => link.to_string(),
            None => format!("{link}#{n_on_link}"),
        });
        n_on_link += 1;
    }
    // The link's mass after its springs: they are the link's compliance (bearings,
    // drive, structure), and the link moves with them.
    if let Some(l) = robot.links.iter().find(|l| l.name == link) {
        b = link_mass(b, l)?;
    }
    Ok(b)
}

/// Adds one chain joint: its fixed origin, then (for a moving joint) its axis, recording
/// its name and limits \[rad or m\]; refuses mimic and unsupported joints.
fn add_chain_joint(
    mut b: ModelBuilder,
    j: &urdf_rs::Joint,
    names: &mut Vec<String>,
    limits: &mut Vec<(f64, f64)>,
) -> Result<ModelBuilder, LoadError> {
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
        // urdf-rs gives a revolute or prismatic joint without `<limit>` the limits
        // (0, 0); the URDF specification requires the element, and a joint that cannot
        // move is not a joint: refuse both.
        if lo.is_nan() || hi.is_nan() || lo >= hi {
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
    Ok(b)
}
