//! A small serial flexible arm for later scenarios: a planar chain of links on revolute-z
//! multibody joints, each driven through a drive spring (stiffness `k[i]`) whose rest angle is
//! the joint command. Its static tip compliance is `J K^-1 J^T` ([`SerialArmSim::linear_compliance`]).

use nalgebra::{DMatrix, Matrix2, Vector2};
use rapier3d_f64::prelude::*;

use crate::SimError;
use crate::robot::DT;

/// Inserts a planar chain of links on revolute-z multibody joints into `world`, on a fixed base
/// at the origin: link `i` has length `links[i].0` and mass properties `links[i].1` (its frame
/// at the joint, x along the link) and is built at relative joint angle `q[i]` [rad].
/// `on_joint(world, joint, i)` runs right after joint `i` is inserted (drive spring, damping).
/// Returns the joints and the link bodies, base to tip; `rejected` is the error if rapier
/// refuses a joint.
pub(crate) fn insert_planar_chain(
    world: &mut PhysicsWorld,
    links: &[(f64, MassProperties)],
    q: &[f64],
    rejected: &str,
    mut on_joint: impl FnMut(&mut PhysicsWorld, MultibodyJointHandle, usize),
) -> Result<(Vec<MultibodyJointHandle>, Vec<RigidBodyHandle>), SimError> {
    let mut parent = world.insert_body(RigidBodyBuilder::fixed());
    let locked = JointAxesMask::LIN_AXES | JointAxesMask::ANG_X | JointAxesMask::ANG_Y;
    let (mut angle, mut at, mut parent_len) = (0.0, Vector::ZERO, 0.0);
    let (mut joints, mut bodies) = (Vec::new(), Vec::new());
    for (i, (&(l, props), &qi)) in links.iter().zip(q).enumerate() {
        angle += qi;
        let body = world.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(Pose::from_parts(at, Rotation::from_rotation_z(angle)))
                .additional_mass_properties(props)
                .can_sleep(false),
        );
        let joint = GenericJointBuilder::new(locked)
            .local_frame1(Pose::from_parts(
                Vector::new(parent_len, 0.0, 0.0),
                Rotation::from_rotation_z(qi),
            ))
            .contacts_enabled(false)
            .build();
        let h = world
            .insert_multibody_joint(parent, body, joint)
            .ok_or_else(|| SimError::new(rejected))?;
        on_joint(world, h, i);
        joints.push(h);
        bodies.push(body);
        at += Rotation::from_rotation_z(angle) * Vector::new(l, 0.0, 0.0);
        parent = body;
        parent_len = l;
    }
    Ok((joints, bodies))
}

/// A planar serial arm with compliant joints in rapier.
pub struct SerialArmSim {
    world: PhysicsWorld,
    lengths: Vec<f64>,
    stiffness: Vec<f64>,
    q_ref: Vec<f64>,
    joints: Vec<MultibodyJointHandle>,
    tip_body: RigidBodyHandle,
}

impl core::fmt::Debug for SerialArmSim {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SerialArmSim")
            .field("lengths", &self.lengths)
            .field("stiffness", &self.stiffness)
            .finish_non_exhaustive()
    }
}

impl SerialArmSim {
    /// Links of `lengths` [m] and `masses` [kg] (uniform rods), joint stiffnesses `stiffness`
    /// [N m/rad], built at absolute-relative joint angles `q` [rad].
    pub fn new(
        lengths: &[f64],
        masses: &[f64],
        stiffness: &[f64],
        q: &[f64],
    ) -> Result<Self, SimError> {
        let n = lengths.len();
        if masses.len() != n || stiffness.len() != n || q.len() != n || n == 0 {
            return Err(SimError::new("serial arm: inconsistent lengths"));
        }
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::ZERO;
        world.integration_parameters.dt = DT;
        let links: Vec<(f64, MassProperties)> = lengths
            .iter()
            .zip(masses)
            .map(|(&l, &m)| {
                let props = MassProperties::new(
                    Vector::new(0.5 * l, 0.0, 0.0),
                    m,
                    Vector::new(1e-5, m * l * l / 12.0, m * l * l / 12.0),
                );
                (l, props)
            })
            .collect();
        let (joints, bodies) = insert_planar_chain(
            &mut world,
            &links,
            q,
            "serial joint rejected",
            |world, h, i| {
                if let Some((mb, id)) = world.multibody_joints.get_mut(h) {
                    if let Some(link) = mb.link_mut(id) {
                        link.joint.set_spring(5, stiffness[i], 0.0);
                    }
                    if let Some(d) = mb.damping_mut().iter_mut().last() {
                        *d = 20.0; // structural damping [N m s/rad]: 10-40 % of critical for the default test arm
                    }
                }
            },
        )?;
        let tip_body = *bodies
            .last()
            .ok_or_else(|| SimError::new("serial arm: no links"))?;
        Ok(Self {
            world,
            lengths: lengths.to_vec(),
            stiffness: stiffness.to_vec(),
            q_ref: q.to_vec(),
            joints,
            tip_body,
        })
    }

    /// Tip position (x, y) [m].
    pub fn tip(&self) -> Vector2<f64> {
        let l = self.lengths.last().copied().unwrap_or(0.0);
        let p = self
            .world
            .bodies
            .get(self.tip_body)
            .map(|rb| rb.position().transform_point(Vector::new(l, 0.0, 0.0)))
            .unwrap_or(Vector::ZERO);
        Vector2::new(p.x, p.y)
    }

    /// One step with joint commands `q` [rad] (spring rest angles) and a tip force [N].
    pub fn step(&mut self, q: &[f64], force: &Vector2<f64>) {
        for (i, h) in self.joints.iter().enumerate() {
            let rest = q.get(i).copied().unwrap_or(0.0) - self.q_ref.get(i).copied().unwrap_or(0.0);
            if let Some((mb, id)) = self.world.multibody_joints.get_mut(*h) {
                if let Some(link) = mb.link_mut(id) {
                    link.joint.set_spring(5, self.stiffness[i], rest);
                }
            }
        }
        let tip = self.tip();
        if let Some(rb) = self.world.bodies.get_mut(self.tip_body) {
            rb.reset_forces(false);
            rb.reset_torques(false);
            rb.add_force_at_point(
                Vector::new(force.x, force.y, 0.0),
                Vector::new(tip.x, tip.y, 0.0),
                false,
            );
        }
        self.world.step();
    }

    /// `J K^-1 J^T` at the reference angles [m/N].
    pub fn linear_compliance(&self) -> Matrix2<f64> {
        let n = self.lengths.len();
        let mut j = DMatrix::zeros(2, n);
        let mut angles = Vec::with_capacity(n);
        let mut a = 0.0;
        for q in &self.q_ref {
            a += q;
            angles.push(a);
        }
        for i in 0..n {
            // Joint i moves links i.. : column = sum over k >= i of L_k * d/dangle (cos, sin).
            let (mut cx, mut cy) = (0.0, 0.0);
            for (l, a) in self.lengths.iter().zip(&angles).skip(i) {
                cx -= l * a.sin();
                cy += l * a.cos();
            }
            j[(0, i)] = cx;
            j[(1, i)] = cy;
        }
        let kinv = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            n,
            self.stiffness.iter().map(|k| 1.0 / k),
        ));
        let c = &j * kinv * j.transpose();
        Matrix2::new(c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)])
    }
}
