//! The milling robot: by default the 6-axis KUKA KR 300 R2500 of Hähn and Weigold (2020,
//! Fig. 2 and Table 1) from deflect's `robots/` files, or any arm of a URDF and stiffness
//! file, simulated by the serial testbed's flexible arm
//! ([`crate::urdf_arm`]: one body per actuated joint and per virtual joint, spring joints,
//! servo-driven motors), with its force/torque sensor frame, a rigid pose IK for the
//! commanded path and the virtual-joint model rebuilt with identified stiffnesses.

use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::io::urdf;
use deflect_core::motion::PoseState;
use deflect_core::vjm::{self, Data, Element, Model, ModelBuilder};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::SimError;
use crate::urdf_arm::{self, ArmSpec, FlexSerialArm, KR300_URDF, RIGID, ServoParams};

/// One virtual joint with a finite stiffness (a body of the simulated arm).
#[derive(Debug, Clone, PartialEq)]
pub struct SpringInfo {
    /// Index of the spring in the chain (deflect-core's order).
    pub index: usize,
    /// Its label (link, `link#n` for the n-th on a link).
    pub label: String,
    /// Stiffnesses about the spring frame's x, y, z \[N m/rad\] (`inf`: rigid).
    pub k: [f64; 3],
}

/// The milling robot (see the module docs).
#[derive(Debug, Clone)]
pub struct MillingArm {
    /// Its name for tables and logs.
    pub name: String,
    /// The arm: bodies and the library model of the same files.
    pub spec: ArmSpec,
    /// The TCP in the force/torque sensor's frame: the URDF's fixed joints after a link
    /// [`SENSOR_LINK`] on the chain, else the identity (the sensor at the TCP).
    pub sensor_to_tcp: Isometry3<f64>,
    /// The finite virtual joints, chain order.
    pub springs: Vec<SpringInfo>,
    rigid: serial::Model,
}

/// The transform from link `from` to its descendant `to` through fixed URDF joints.
fn fixed_transform(robot: &urdf_rs::Robot, from: &str, to: &str) -> Result<Isometry3<f64>, String> {
    let mut t = Isometry3::identity();
    let mut at = to;
    for _ in 0..=robot.joints.len() {
        if at == from {
            return Ok(t);
        }
        let j = robot
            .joints
            .iter()
            .find(|j| j.child.link == at)
            .ok_or_else(|| format!("no joint leads to link '{at}'"))?;
        if j.joint_type != urdf_rs::JointType::Fixed {
            return Err(format!(
                "joint '{}' between {from} and {to} is not fixed",
                j.name
            ));
        }
        let (xyz, rpy) = (j.origin.xyz.0, j.origin.rpy.0);
        t = Isometry3::from_parts(
            Translation3::new(xyz[0], xyz[1], xyz[2]),
            UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
        ) * t;
        at = j.parent.link.as_str();
    }
    Err(format!("link '{to}' does not descend from '{from}'"))
}

/// The link whose frame is the force/torque sensor's, when the URDF has one.
pub const SENSOR_LINK: &str = "ft_sensor";

impl MillingArm {
    /// The built-in KR 300 R2500 (URDF and stiffness file of `robots/`), TCP at the tool tip,
    /// sensor at link `ft_sensor`.
    pub fn kr300() -> Result<Self, SimError> {
        let spec = urdf_arm::kr300()?;
        let parsed = urdf::parse(KR300_URDF)?;
        Self::from_spec("KR 300 R2500", spec, &parsed, "tcp")
    }

    /// Any arm: `spec` built from a URDF and stiffness file ([`urdf_arm::arm_spec`]), `parsed`
    /// the same URDF, `tip` the TCP link. The sensor is at link [`SENSOR_LINK`] when the URDF
    /// has it between a fixed-joint run and the tip, else at the TCP.
    pub fn from_spec(
        name: &str,
        spec: ArmSpec,
        parsed: &urdf_rs::Robot,
        tip: &str,
    ) -> Result<Self, SimError> {
        let sensor_to_tcp = if parsed.links.iter().any(|l| l.name == SENSOR_LINK) {
            fixed_transform(parsed, SENSOR_LINK, tip)
                .map_err(|e| SimError::new(format!("{name}: sensor frame: {e}")))?
        } else {
            Isometry3::identity()
        };
        let model = &spec.robot.model;
        let springs = model
            .elements()
            .iter()
            .filter_map(|e| match *e {
                Element::Spring {
                    compliance, index, ..
                } if compliance.iter().any(|&c| c > 1.0 / RIGID) => Some(SpringInfo {
                    index,
                    label: spec
                        .robot
                        .spring_names
                        .get(index)
                        .cloned()
                        .unwrap_or_default(),
                    k: compliance
                        .map(|c| if c > 0.0 { 1.0 / c } else { f64::INFINITY })
                        .into(),
                }),
                _ => None,
            })
            .collect();
        let rigid = serial::Model::new(model.clone(), Payload::point(0.0, Vector3::zeros()))?
            .with_joint_limits(&spec.robot.joint_limits)?;
        Ok(Self {
            name: name.to_string(),
            spec,
            sensor_to_tcp,
            springs,
            rigid,
        })
    }

    /// The virtual-joint model with the files' stiffnesses.
    pub fn model(&self) -> &Model {
        &self.spec.robot.model
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.model().dof()
    }

    /// The rigid TCP pose at joints `q`.
    pub fn forward(&self, q: &[f64]) -> Result<Isometry3<f64>, SimError> {
        Ok(vjm::forward(self.model(), &mut Data::new(self.model()), q)?)
    }

    /// The workspace of [`Self::ik`], warm-started from joints `seed`.
    pub fn ik_data(&self, seed: &[f64]) -> serial::Data {
        let mut d = serial::Data::new(&self.rigid);
        d.set_seed(seed);
        d
    }

    /// Joints that put the rigid TCP on `pose` (damped-least-squares pose IK, warm-started
    /// from the last solution in `data`, within the joint limits).
    pub fn ik(&self, data: &mut serial::Data, pose: &Isometry3<f64>) -> Result<Vec<f64>, SimError> {
        let tick = serial::step(&self.rigid, data, &PoseState::at_rest(0.0, *pose), None)
            .map_err(|e| SimError::new(format!("milling IK: {e}")))?;
        Ok(tick.joints.iter().take(self.dof()).copied().collect())
    }

    /// The arm in rapier at rest at `q0`, physics step `dt` in `substeps` rapier substeps,
    /// every damping times `damping_scale` (> 1 settles static tests quickly), carrying
    /// `spindle` beyond the TCP (TCP frame) when given.
    pub fn sim(
        &self,
        q0: &[f64],
        damping_scale: f64,
        (dt, substeps): (f64, usize),
        spindle: Option<&Payload>,
    ) -> Result<FlexSerialArm, SimError> {
        let servo = ServoParams {
            dt,
            substeps,
            ..ServoParams::default()
        };
        FlexSerialArm::new(&self.spec, q0, spindle, &servo, damping_scale)
    }

    /// The sensor's pose in the simulated arm (base frame).
    pub fn sensor_pose(&self, sim: &FlexSerialArm) -> Isometry3<f64> {
        sim.tcp_pose() * self.sensor_to_tcp.inverse()
    }

    /// The model with the stiffness of spring `s` about axis `a` replaced by `k` for every
    /// `(s, a, k)` in `identified` (values that are not finite and positive are skipped).
    pub fn model_with(&self, identified: &[(usize, usize, f64)]) -> Result<Model, SimError> {
        let mut b = ModelBuilder::new();
        for e in self.model().elements() {
            b = match *e {
                Element::Fixed(t) => b.fixed(t)?,
                Element::Revolute { axis, .. } => b.revolute(axis.into_inner())?,
                Element::Prismatic { axis, .. } => b.prismatic(axis.into_inner())?,
                Element::Spring {
                    compliance,
                    index,
                    offset,
                } => {
                    let mut k: [f64; 3] = compliance
                        .map(|c| if c > 0.0 { 1.0 / c } else { f64::INFINITY })
                        .into();
                    for &(s, a, v) in identified {
                        if s == index
                            && v.is_finite()
                            && v > 0.0
                            && let Some(ka) = k.get_mut(a)
                        {
                            *ka = v;
                        }
                    }
                    b.spring_at(offset, k)?
                }
                Element::Mass {
                    mass, com, inertia, ..
                } => b.mass(mass, com, inertia)?,
            };
        }
        Ok(b.build()?)
    }
}
