//! The rapier multibody of an [`ArmSpec`]: one dynamic body per piece (actuated joint or
//! virtual joint), each hung on the previous one by a multibody joint with its springs and
//! per-DOF damping, the link masses (and a payload) on the bodies (see the `sim` module).

use deflect_core::dalembert::serial::Payload;
use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};
use rapier3d_f64::prelude::*;

use super::spec::{ArmSpec, Body, Inertia, Piece, RIGID};
use crate::SimError;
use crate::rapier_util::{ANG_X, ANG_Y, ANG_Z, LIN_X, new_world, set_spring};

/// The constants the chain's joints and bodies are built with.
pub(super) struct ChainParams {
    /// Drive-spring stiffness \[N m/rad\] (N/m for a prismatic joint).
    pub k_drive: f64,
    /// Drive damping \[N m s/rad\] (N s/m for a prismatic joint).
    pub c_drive: f64,
    /// Stiffness-proportional damping of the virtual joints, `c = beta k` \[s\].
    pub beta: f64,
    /// Multiplies every virtual joint's damping.
    pub damping_scale: f64,
    /// Mass of a body that carries no URDF link \[kg\].
    pub filler: f64,
    /// A rigid axis among three free rotations gets this many times the joint's stiffest.
    pub stiff_ratio: f64,
    /// Time step \[s\].
    pub dt: f64,
    /// rapier substeps per time step.
    pub substeps: usize,
}

/// The built chain: the world and, per body, its handles and roles.
pub(super) struct Chain {
    /// The physics world with the fixed base and the chain's bodies.
    pub world: PhysicsWorld,
    /// The chain's bodies, base to tip.
    pub bodies: Vec<RigidBodyHandle>,
    /// The multibody joint of each body.
    pub joints: Vec<MultibodyJointHandle>,
    /// Body index of each actuated joint, in `q` order.
    pub actuated: Vec<usize>,
    /// Joint axis of each actuated joint in its body frame.
    pub axes: Vec<Vector3<f64>>,
    /// Body index and attachment (in the previous body) of each virtual joint, chain order.
    pub springs: Vec<(usize, Isometry3<f64>)>,
}

/// One body's multibody joint: its frames, locked axes and springs `(axis, k, c)`.
struct JointPlan {
    frame1: Isometry3<f64>,
    frame2: Isometry3<f64>,
    locked: JointAxesMask,
    springs: Vec<(usize, f64, f64)>,
}

/// The rapier pose of a nalgebra isometry.
fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// The rapier mass properties of a body's lumped inertia.
fn mass_properties(i: &Inertia) -> MassProperties {
    let m = &i.inertia;
    let cols = [
        m[(0, 0)],
        m[(1, 0)],
        m[(2, 0)],
        m[(0, 1)],
        m[(1, 1)],
        m[(2, 1)],
        m[(0, 2)],
        m[(1, 2)],
        m[(2, 2)],
    ];
    MassProperties::with_inertia_matrix(
        Vector::new(i.com.x, i.com.y, i.com.z),
        i.mass,
        Matrix::from_cols_array(&cols),
    )
}

/// The chain of `spec` at joints `q0` \[rad\] in a new world, `payload` on the last body.
pub(super) fn build_chain(
    spec: &ArmSpec,
    q0: &[f64],
    payload: Option<&Payload>,
    p: &ChainParams,
) -> Result<Chain, SimError> {
    let mut world = new_world(Vector::ZERO, p.dt);
    world.integration_parameters.num_solver_iterations = p.substeps;
    let mut parent = world.insert_body(RigidBodyBuilder::fixed());
    let mut at = Isometry3::identity();
    let (mut bodies, mut joints, mut actuated, mut axes, mut spring_bodies) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let last = spec.bodies.len().saturating_sub(1);
    let mut qi = 0usize;
    for (index, b) in spec.bodies.iter().enumerate() {
        let inertia = body_inertia(b, if index == last { payload } else { None }, spec, p);
        let plan = match &b.piece {
            Piece::Revolute { axis, .. } => {
                let q = q0.get(qi).copied().unwrap_or(0.0);
                qi += 1;
                actuated.push(index);
                axes.push(axis.into_inner());
                revolute_joint(b, axis, q, p)
            }
            Piece::Spring { k, .. } => {
                spring_bodies.push((index, b.attach));
                spring_joint(b, k, p)
            }
            Piece::Prismatic { axis, .. } => {
                let q = q0.get(qi).copied().unwrap_or(0.0);
                qi += 1;
                actuated.push(index);
                axes.push(axis.into_inner());
                prismatic_joint(b, axis, q, p)
            }
        };
        at *= body_offset(b, q0.get(qi.saturating_sub(1)).copied().unwrap_or(0.0));
        let body = world.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(to_pose(&at))
                .additional_mass_properties(mass_properties(&inertia))
                .can_sleep(false),
        );
        let joint = GenericJointBuilder::new(plan.locked)
            .local_frame1(to_pose(&plan.frame1))
            .local_frame2(to_pose(&plan.frame2))
            .contacts_enabled(false)
            .build();
        let h = world
            .insert_multibody_joint(parent, body, joint)
            .ok_or_else(|| SimError::new(format!("rapier refused the joint of body {index}")))?;
        set_springs_and_damping(&mut world, h, &plan.springs, &b.piece, p);
        bodies.push(body);
        joints.push(h);
        parent = body;
    }
    Ok(Chain {
        world,
        bodies,
        joints,
        actuated,
        axes,
        springs: spring_bodies,
    })
}

/// The body's mass properties: its links, plus `payload` (TCP frame), or a filler.
fn body_inertia(b: &Body, payload: Option<&Payload>, spec: &ArmSpec, p: &ChainParams) -> Inertia {
    let mut inertia = b.inertia;
    if let Some(pl) = payload {
        inertia.add(
            &Inertia {
                mass: pl.mass,
                com: pl.com,
                inertia: pl.inertia,
            },
            &spec.tcp,
        );
    }
    if inertia.mass <= 0.0 {
        let m = p.filler;
        inertia = Inertia {
            mass: m,
            com: Vector3::zeros(),
            inertia: Matrix3::identity() * (0.4 * m * 0.05 * 0.05),
        };
    }
    inertia
}

/// The rotation taking x onto the joint `axis` (a half turn about z for `-x`).
fn align_x(axis: &Unit<Vector3<f64>>) -> Isometry3<f64> {
    let align = UnitQuaternion::rotation_between(&Vector3::x(), axis).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), core::f64::consts::PI)
    });
    Isometry3::from_parts(Translation3::identity(), align)
}

/// An actuated revolute joint about `axis` at angle `q` \[rad\]: free about x, drive spring.
fn revolute_joint(b: &Body, axis: &Unit<Vector3<f64>>, q: f64, p: &ChainParams) -> JointPlan {
    let align = align_x(axis);
    let turn = Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(axis, q),
    );
    JointPlan {
        frame1: b.attach * turn * align,
        frame2: align,
        locked: JointAxesMask::LIN_AXES | JointAxesMask::ANG_Y | JointAxesMask::ANG_Z,
        springs: vec![(ANG_X, p.k_drive, 0.0)],
    }
}

/// An actuated prismatic joint along `axis` at `q` \[m\]: free along x, drive spring.
fn prismatic_joint(b: &Body, axis: &Unit<Vector3<f64>>, q: f64, p: &ChainParams) -> JointPlan {
    let align = align_x(axis);
    let slide = Isometry3::from_parts(
        Translation3::from(axis.into_inner() * q),
        UnitQuaternion::identity(),
    );
    JointPlan {
        frame1: b.attach * slide * align,
        frame2: align,
        locked: JointAxesMask::LIN_Y
            | JointAxesMask::LIN_Z
            | JointAxesMask::ANG_X
            | JointAxesMask::ANG_Y
            | JointAxesMask::ANG_Z,
        springs: vec![(LIN_X, p.k_drive, 0.0)],
    }
}

/// A virtual joint of stiffnesses `k` \[N m/rad\]: one free rotation or all three, sprung.
fn spring_joint(b: &Body, k: &[f64; 3], p: &ChainParams) -> JointPlan {
    let finite: Vec<usize> = (0..3).filter(|&a| k[a] < RIGID).collect();
    let stiffest = finite.iter().map(|&a| k[a]).fold(0.0f64, f64::max);
    let names = [ANG_X, ANG_Y, ANG_Z];
    let (locked, springs) = if finite.len() == 1 {
        let a = finite.first().copied().unwrap_or(0);
        let lock = [
            JointAxesMask::ANG_X,
            JointAxesMask::ANG_Y,
            JointAxesMask::ANG_Z,
        ]
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != a)
        .fold(JointAxesMask::LIN_AXES, |m, (_, x)| m | *x);
        (lock, vec![(names[a], k[a], p.beta * k[a])])
    } else {
        let springs = (0..3)
            .map(|a| {
                let ka = if k[a] < RIGID {
                    k[a]
                } else {
                    p.stiff_ratio * stiffest
                };
                (names[a], ka, p.beta * ka)
            })
            .collect();
        (JointAxesMask::LIN_AXES, springs)
    };
    JointPlan {
        frame1: b.attach,
        frame2: Isometry3::identity(),
        locked,
        springs,
    }
}

/// The body's pose in the previous body's: its attachment, moved by the joint's `q`.
fn body_offset(b: &Body, q: f64) -> Isometry3<f64> {
    match &b.piece {
        Piece::Revolute { axis, .. } => {
            b.attach
                * Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(axis, q),
                )
        }
        Piece::Prismatic { axis, .. } => b.attach * Translation3::from(axis.into_inner() * q),
        Piece::Spring { .. } => b.attach,
    }
}

/// Sets the joint's springs and its free DOFs' damping (drive or `c` times the scale).
fn set_springs_and_damping(
    world: &mut PhysicsWorld,
    h: MultibodyJointHandle,
    springs: &[(usize, f64, f64)],
    piece: &Piece,
    p: &ChainParams,
) {
    for (axis, stiffness, _) in springs {
        set_spring(world, h, *axis, *stiffness, 0.0);
    }
    // Per-DOF damping: the joint's free DOFs are its last ones so far, in axis order.
    if let Some((mb, _)) = world.multibody_joints.get_mut(h) {
        let n = mb.damping_mut().len();
        let dampings: Vec<f64> = springs
            .iter()
            .map(|(_, _, c)| match piece {
                // The drive's damping `c (w_link - w_motor)`: the link part is
                // implicit here, the motor part an explicit torque (`FlexSerialArm::apply`).
                Piece::Revolute { .. } | Piece::Prismatic { .. } => p.c_drive,
                Piece::Spring { .. } => *c * p.damping_scale,
            })
            .collect();
        let start = n.saturating_sub(dampings.len());
        for (d, c) in mb.damping_mut().iter_mut().skip(start).zip(&dampings) {
            *d = *c;
        }
    }
}
