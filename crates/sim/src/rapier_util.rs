//! rapier3d-f64 helpers shared by every scene: world set-up, conversions of rapier's poses to
//! nalgebra, the state and springs of multibody joints, body points, and the planar chain of
//! revolute-z links used by the serial arm and the contour arm.

use deflect_core::units::GRAVITY_Z_DOWN;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;

use crate::SimError;

/// The servo step of the scenes \[s\]: the 2 kHz of Paksoy, Dede and Kiper's controller.
pub const SERVO_DT: f64 = 1.0 / 2000.0;

/// Index of the rotation about the joint frame's x axis among a generic joint's six
/// coordinates (`LinX, LinY, LinZ, AngX, AngY, AngZ`).
pub const ANG_X: usize = 3;
/// Index of the translation along x (see [`ANG_X`]).
pub const LIN_X: usize = 0;
/// Index of the rotation about y (see [`ANG_X`]).
pub const ANG_Y: usize = 4;
/// Index of the rotation about z (see [`ANG_X`]).
pub const ANG_Z: usize = 5;

/// Standard gravity down the world z axis, [`deflect_core::units::GRAVITY_Z_DOWN`], as a
/// rapier vector \[m/s^2\].
pub fn gravity_z_down() -> Vector {
    let [x, y, z] = GRAVITY_Z_DOWN;
    Vector::new(x, y, z)
}

/// An empty world with gravity `gravity` \[m/s^2\] and time step `dt` \[s\].
pub fn new_world(gravity: Vector, dt: f64) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = gravity;
    world.integration_parameters.dt = dt;
    world
}

/// A rapier vector as nalgebra's.
pub fn to_na(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

/// A rapier rotation as nalgebra's unit quaternion.
pub fn rot_na(q: Rotation) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q.w, q.x, q.y, q.z))
}

/// A rapier pose as nalgebra's isometry.
pub fn pose_na(p: &Pose) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(to_na(p.translation)), rot_na(p.rotation))
}

/// Pose of `body` in the world, `None` if the body does not exist.
pub fn body_pose(world: &PhysicsWorld, body: RigidBodyHandle) -> Option<Isometry3<f64>> {
    world.bodies.get(body).map(|rb| pose_na(rb.position()))
}

/// World position \[m\] of the point `local` of `body` (the origin if the body does not
/// exist).
pub fn body_point(world: &PhysicsWorld, body: RigidBodyHandle, local: Vector) -> Vector3<f64> {
    to_na(
        world
            .bodies
            .get(body)
            .map(|rb| rb.position().transform_point(local))
            .unwrap_or(Vector::ZERO),
    )
}

/// Sets the spring of coordinate `axis` ([`ANG_X`], [`ANG_Y`], [`ANG_Z`], ...) of the
/// multibody joint `joint`: stiffness `stiffness` about the rest value `rest` (relative to the
/// pose the joint was built in). Does nothing if the joint does not exist.
pub fn set_spring(
    world: &mut PhysicsWorld,
    joint: MultibodyJointHandle,
    axis: usize,
    stiffness: f64,
    rest: f64,
) {
    if let Some((mb, id)) = world.multibody_joints.get_mut(joint)
        && let Some(link) = mb.link_mut(id)
    {
        link.joint.set_spring(axis, stiffness, rest);
    }
}

/// Sets the generalized damping of the last degree of freedom of the multibody that holds
/// `joint`: the joint's own when it was the last one inserted and has one degree of freedom.
pub fn set_last_dof_damping(world: &mut PhysicsWorld, joint: MultibodyJointHandle, damping: f64) {
    if let Some((mb, _)) = world.multibody_joints.get_mut(joint)
        && let Some(d) = mb.damping_mut().iter_mut().last()
    {
        *d = damping;
    }
}

/// Coordinate and rate of a revolute-z multibody joint (relative to the pose it was built
/// in) \[rad, rad/s\]; `None` if the joint does not exist.
pub fn revolute_z_state(world: &PhysicsWorld, joint: MultibodyJointHandle) -> Option<(f64, f64)> {
    let (mb, id) = world.multibody_joints.get(joint)?;
    let link = mb.link(id)?;
    let angle = link.joint().coords()[ANG_Z];
    let rate = mb.joint_velocity(link).get(0).copied().unwrap_or(0.0);
    Some((angle, rate))
}

/// Inserts a planar chain of links on revolute-z multibody joints into `world`, on a fixed base
/// at the origin: link `i` has length `links[i].0` and mass properties `links[i].1` (its frame
/// at the joint, x along the link) and is built at relative joint angle `q[i]` \[rad\].
/// `on_joint(world, joint, i)` runs right after joint `i` is inserted (drive spring, damping).
/// Returns the joints and the link bodies, base to tip; `rejected` is the error if rapier
/// refuses a joint.
pub fn insert_planar_chain(
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
