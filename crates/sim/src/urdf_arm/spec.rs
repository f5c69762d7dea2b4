//! The arm's description for the testbed, read from a URDF and a stiffness file: the chain of
//! bodies (one per actuated joint and one per virtual joint), where each attaches, and the
//! mass properties of the URDF links lumped onto them.
//!
//! The chain is the virtual-joint model's (deflect-core's `io::urdf::assemble`, which also
//! validates both files first): along the base-to-tip path, each URDF joint's origin, then the
//! actuated joint, then the child link's springs in file order, each spring frame relative to
//! the link frame and turning the rest of the chain about its origin. Every actuated joint
//! and every spring with a finite stiffness starts a new rigid body whose frame is the joint
//! (or spring) frame; fixed URDF joints and rigid springs add nothing but a transform.

use std::collections::HashMap;

use deflect_core::SerialRobot;
use deflect_core::io::{stiffness, urdf};
use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use crate::SimError;

/// A stiffness at or above this \[N m/rad\] is rigid in the testbed (the KR 300 file's tool
/// spring is 9.9e96, "rigid" in the paper's Table 1).
pub const RIGID: f64 = 1.0e12;

/// Mass properties of one body in its own frame: mass \[kg\], centre of mass \[m\] and inertia
/// about the centre of mass \[kg m^2\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inertia {
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre of mass in the body frame \[m\].
    pub com: Vector3<f64>,
    /// Inertia tensor about the centre of mass, body axes \[kg m^2\].
    pub inertia: Matrix3<f64>,
}

impl Inertia {
    /// No mass.
    pub fn zero() -> Self {
        Self {
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        }
    }

    /// `other`, given in a frame at `pose` in this body's frame, added to this one (parallel
    /// axis theorem).
    pub fn add(&mut self, other: &Inertia, pose: &Isometry3<f64>) {
        if other.mass <= 0.0 {
            return;
        }
        let r = pose.rotation.to_rotation_matrix();
        let com_o = pose * nalgebra::Point3::from(other.com);
        let i_o = r.matrix() * other.inertia * r.matrix().transpose();
        let m = self.mass + other.mass;
        let com = (self.com * self.mass + com_o.coords * other.mass) / m;
        let shift = |mass: f64, d: Vector3<f64>| {
            (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * mass
        };
        self.inertia = self.inertia
            + shift(self.mass, self.com - com)
            + i_o
            + shift(other.mass, com_o.coords - com);
        self.com = com;
        self.mass = m;
    }
}

/// What joins a body to the one before it.
#[derive(Debug, Clone, PartialEq)]
pub enum Piece {
    /// An actuated revolute joint about the unit `axis` (body frame); built at angle `q0`.
    Revolute {
        /// URDF joint name.
        name: String,
        /// Joint axis in the joint frame.
        axis: Unit<Vector3<f64>>,
    },
    /// An actuated prismatic joint along the unit `axis` (body frame); built at `q0` \[m\].
    Prismatic {
        /// URDF joint name.
        name: String,
        /// Joint axis in the joint frame.
        axis: Unit<Vector3<f64>>,
    },
    /// A virtual joint: stiffnesses about the body frame's x, y, z \[N m/rad\] (`inf` or
    /// >= [`RIGID`]: rigid about that axis; at least one is finite).
    Spring {
        /// The spring's label (the joint name for `joint = ...` springs, else the link).
        name: String,
        /// Stiffnesses \[N m/rad\].
        k: [f64; 3],
    },
}

/// One body of the chain.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// How it is joined to the previous body (the fixed base for the first).
    pub piece: Piece,
    /// Pose of this body's frame (before the joint's own motion) in the previous body's frame.
    pub attach: Isometry3<f64>,
    /// The URDF links lumped onto this body, with their mass properties in its frame.
    pub inertia: Inertia,
    /// Names of those links.
    pub links: Vec<String>,
}

/// The arm: bodies base to tip, the TCP in the last body's frame, and the library model.
#[derive(Debug, Clone)]
pub struct ArmSpec {
    /// Bodies, base to tip.
    pub bodies: Vec<Body>,
    /// TCP (tip link frame) in the last body's frame.
    pub tcp: Isometry3<f64>,
    /// The virtual-joint model of the same files (deflect-core).
    pub robot: SerialRobot,
    /// Mass of the links the testbed could not place (on the fixed base) \[kg\].
    pub base_mass: f64,
}

fn pose(xyz: &[f64; 3], rpy: &[f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

fn link_inertia(link: &urdf_rs::Link) -> Inertia {
    let i = &link.inertial;
    let t = pose(&i.origin.xyz.0, &i.origin.rpy.0);
    let m = &i.inertia;
    let local = Inertia {
        mass: i.mass.value,
        com: Vector3::zeros(),
        inertia: Matrix3::new(
            m.ixx, m.ixy, m.ixz, m.ixy, m.iyy, m.iyz, m.ixz, m.iyz, m.izz,
        ),
    };
    let mut out = Inertia::zero();
    out.add(&local, &t);
    out
}

/// Reads the arm from the URDF and stiffness texts; the chain runs from the URDF root (or
/// `base_link`) to `tip_link`. Both files are validated by deflect-core first (the error names
/// what is wrong). Revolute, continuous, prismatic and fixed joints are built.
pub fn arm_spec(
    urdf_text: &str,
    stiffness_text: &str,
    base_link: Option<&str>,
    tip_link: &str,
) -> Result<ArmSpec, SimError> {
    let robot = urdf::from_str(urdf_text, stiffness_text, base_link, tip_link)?;
    let parsed = urdf::parse(urdf_text)?;
    let springs = stiffness::from_str(stiffness_text)?;
    let links: HashMap<&str, &urdf_rs::Link> =
        parsed.links.iter().map(|l| (l.name.as_str(), l)).collect();
    let (path, base) = chain_path(&parsed, base_link, tip_link);
    let mut chain = Lumping {
        links,
        on_link: springs_by_link(&springs, &parsed)?,
        bodies: Vec::new(),
        base_inertia: Inertia::zero(),
        offset: Isometry3::identity(),
    };
    chain.add_link(base);
    for j in &path {
        chain.offset *= pose(&j.origin.xyz.0, &j.origin.rpy.0);
        if let Some(body) = joint_body(j, chain.offset)? {
            chain.bodies.push(body);
            chain.offset = Isometry3::identity();
        }
        chain.add_link(&j.child.link);
    }
    Ok(ArmSpec {
        bodies: chain.bodies,
        tcp: chain.offset,
        robot,
        base_mass: chain.base_inertia.mass,
    })
}

/// A spring of a link: its frame in the link, stiffnesses \[N m/rad\] and name.
type Spring = (Isometry3<f64>, [f64; 3], String);

/// The URDF joints on the path base -> tip, base first, and the base link (deflect-core has
/// checked that the path exists).
fn chain_path<'a>(
    parsed: &'a urdf_rs::Robot,
    base_link: Option<&str>,
    tip_link: &'a str,
) -> (Vec<&'a urdf_rs::Joint>, &'a str) {
    let by_child: HashMap<&str, &urdf_rs::Joint> = parsed
        .joints
        .iter()
        .map(|j| (j.child.link.as_str(), j))
        .collect();
    let mut path = Vec::new();
    let mut link = tip_link;
    while Some(link) != base_link {
        match by_child.get(link) {
            Some(j) => {
                path.push(*j);
                link = j.parent.link.as_str();
            }
            None => break,
        }
    }
    path.reverse();
    (path, link)
}

/// The springs of each link, in file order (a joint's spring on the joint's child link).
fn springs_by_link(
    springs: &[stiffness::VirtualJointSpec],
    parsed: &urdf_rs::Robot,
) -> Result<HashMap<String, Vec<Spring>>, SimError> {
    let joints_by_name: HashMap<&str, &urdf_rs::Joint> =
        parsed.joints.iter().map(|j| (j.name.as_str(), j)).collect();
    let mut on_link: HashMap<String, Vec<Spring>> = HashMap::new();
    for s in springs {
        let (link, frame, name) = match (&s.link, &s.joint) {
            (Some(l), _) => (
                l.clone(),
                pose(&s.xyz.unwrap_or([0.0; 3]), &s.rpy.unwrap_or([0.0; 3])),
                l.clone(),
            ),
            (None, Some(j)) => {
                let joint = joints_by_name
                    .get(j.as_str())
                    .ok_or_else(|| SimError::new(format!("unknown joint '{j}'")))?;
                let axis = Vector3::from(joint.axis.xyz.0).normalize();
                (
                    joint.child.link.clone(),
                    urdf::joint_spring_frame(&axis),
                    j.clone(),
                )
            }
            (None, None) => return Err(SimError::new("a spring without link or joint")),
        };
        on_link.entry(link).or_default().push((frame, s.k, name));
    }
    Ok(on_link)
}

/// The chain being built: the bodies so far, the links lumped on the fixed base, and the
/// pose of the current virtual-joint-model frame in the current body's frame.
struct Lumping<'a> {
    links: HashMap<&'a str, &'a urdf_rs::Link>,
    on_link: HashMap<String, Vec<Spring>>,
    bodies: Vec<Body>,
    base_inertia: Inertia,
    offset: Isometry3<f64>,
}

impl Lumping<'_> {
    /// Adds the link `name`: its springs first (each a new body), then its mass on the last
    /// body (or the base).
    fn add_link(&mut self, name: &str) {
        for (frame, k, label) in self.on_link.get(name).map(Vec::as_slice).unwrap_or(&[]) {
            if k.iter().all(|v| *v >= RIGID) {
                continue;
            }
            self.bodies.push(Body {
                piece: Piece::Spring {
                    name: label.clone(),
                    k: *k,
                },
                attach: self.offset * frame,
                inertia: Inertia::zero(),
                links: Vec::new(),
            });
            self.offset = frame.inverse();
        }
        if let Some(l) = self.links.get(name) {
            let li = link_inertia(l);
            match self.bodies.last_mut() {
                Some(b) => {
                    b.inertia.add(&li, &self.offset);
                    b.links.push(name.to_string());
                }
                None => self.base_inertia.add(&li, &self.offset),
            }
        }
    }
}

/// The body an actuated URDF joint starts, attached at `attach`; none for a fixed joint.
fn joint_body(j: &urdf_rs::Joint, attach: Isometry3<f64>) -> Result<Option<Body>, SimError> {
    let piece = match j.joint_type {
        urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => Piece::Revolute {
            name: j.name.clone(),
            axis: Unit::new_normalize(Vector3::from(j.axis.xyz.0)),
        },
        urdf_rs::JointType::Prismatic => Piece::Prismatic {
            name: j.name.clone(),
            axis: Unit::new_normalize(Vector3::from(j.axis.xyz.0)),
        },
        urdf_rs::JointType::Fixed => return Ok(None),
        ref other => {
            return Err(SimError::new(format!(
                "joint '{}': the testbed builds revolute, continuous, prismatic and fixed \
                 joints only, not {}",
                j.name,
                format!("{other:?}").to_lowercase()
            )));
        }
    };
    Ok(Some(Body {
        piece,
        attach,
        inertia: Inertia::zero(),
        links: Vec::new(),
    }))
}
