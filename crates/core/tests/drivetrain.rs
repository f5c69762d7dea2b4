//! Drive-train errors (Eq. 3-13 of the contour-tracking paper): gravity torques against the
//! potential energy, Eq. 10 against hand computations, `K = J^-T K_theta J^-1` against the
//! compliance of a VJM model with springs about the joint axes, and the TOML/URDF loader.

use approx::assert_relative_eq;
use deflect_core::drivetrain::{
    self, LinkMasses, cartesian_stiffness, cartesian_stiffness_planar, cartesian_stiffness_xy,
    gravity_torques,
};
use deflect_core::io;
use deflect_core::units::STANDARD_GRAVITY;
use deflect_core::vjm::{self, Data};
use deflect_core::{BuildError, Model, ModelBuilder, SerialRobot, TickError};
use nalgebra::{Isometry3, Matrix2, Matrix6, Vector3, Vector6};

mod fixtures;

/// The joints of a 6-axis arm with a prismatic track: (axis, revolute?, link offset).
fn arm_joints() -> [(Vector3<f64>, bool, Vector3<f64>); 6] {
    [
        (Vector3::z(), true, Vector3::new(0.1, 0.0, 0.4)),
        (Vector3::y(), true, Vector3::new(0.6, 0.05, 0.0)),
        (
            Vector3::new(1.0, 0.0, 0.0),
            false,
            Vector3::new(0.0, 0.0, 0.1),
        ),
        (Vector3::y(), true, Vector3::new(0.5, 0.0, 0.05)),
        (
            Vector3::new(1.0, 1.0, 0.0),
            true,
            Vector3::new(0.2, -0.1, 0.0),
        ),
        (Vector3::x(), true, Vector3::new(0.1, 0.0, 0.0)),
    ]
}

/// The chain up to (and including) joint `upto`, then a fixed offset `tail`.
fn arm(upto: usize, tail: Vector3<f64>) -> Model {
    let mut b = ModelBuilder::new()
        .fixed(Isometry3::translation(0.0, 0.0, 0.3))
        .unwrap();
    for (i, (axis, rev, off)) in arm_joints().into_iter().enumerate().take(upto + 1) {
        b = if rev {
            b.revolute(axis)
        } else {
            b.prismatic(axis)
        }
        .unwrap();
        if i < upto {
            b = b
                .fixed(Isometry3::translation(off.x, off.y, off.z))
                .unwrap();
        }
    }
    b.fixed(Isometry3::translation(tail.x, tail.y, tail.z))
        .unwrap()
        .build()
        .unwrap()
}

/// The masses: (after joint, kg, CoM in the frame after that joint).
fn arm_masses() -> [(usize, f64, Vector3<f64>); 7] {
    [
        (0, 30.0, Vector3::new(0.05, 0.0, 0.2)),
        (1, 20.0, Vector3::new(0.3, 0.02, 0.0)),
        (2, 5.0, Vector3::new(0.0, 0.01, 0.05)),
        (3, 8.0, Vector3::new(0.25, 0.0, 0.02)),
        (4, 3.0, Vector3::new(0.1, -0.05, 0.0)),
        (5, 2.0, Vector3::new(0.05, 0.0, 0.0)),
        (5, 4.0, Vector3::new(0.15, 0.02, -0.03)), // a tool on the flange
    ]
}

fn potential(q: &[f64], g: &Vector3<f64>) -> f64 {
    // Independent: the CoM position from the forward kinematics of a truncated chain.
    arm_masses()
        .iter()
        .map(|&(j, m, com)| {
            let sub = arm(j, com);
            let p = vjm::forward(&sub, &mut Data::new(&sub), &q[..=j]).unwrap();
            -m * g.dot(&p.translation.vector)
        })
        .sum()
}

#[test]
fn gravity_torques_are_the_gradient_of_the_potential_energy() {
    let model = arm(5, Vector3::new(0.1, 0.0, 0.0));
    let mut masses = LinkMasses::new();
    for (j, m, c) in arm_masses() {
        masses.push(j, m, c).unwrap();
    }
    for g in [Vector3::new(0.0, 0.0, -9.81), Vector3::new(1.2, -3.0, -9.0)] {
        let drive = drivetrain::Model::new(model.clone(), &[1e5; 6], &[0.0; 6])
            .unwrap()
            .with_masses(masses.clone())
            .unwrap()
            .with_gravity(g)
            .unwrap();
        let mut data = drivetrain::Data::new(&drive);
        for q in [
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.3, -0.7, 0.12, 1.1, -0.4, 0.9],
            [-1.2, 0.5, -0.05, -0.8, 2.0, -1.5],
        ] {
            let tau = gravity_torques(&drive, &mut data, &q).unwrap();
            let h = 1e-6;
            for j in 0..6 {
                let (mut qp, mut qm) = (q, q);
                qp[j] += h;
                qm[j] -= h;
                let fd = (potential(&qp, &g) - potential(&qm, &g)) / (2.0 * h);
                assert_relative_eq!(tau[j], fd, epsilon = 1e-6, max_relative = 1e-7);
            }
        }
    }
}

/// Two joints about y, links along x: written out by hand.
#[test]
fn eq10_gravity_hand_example() {
    let model = ModelBuilder::new()
        .revolute(Vector3::y())
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .fixed(Isometry3::translation(0.5, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let masses = LinkMasses::new()
        .with(0, 2.0, Vector3::new(0.5, 0.0, 0.0))
        .unwrap()
        .with(1, 1.0, Vector3::new(0.25, 0.0, 0.0))
        .unwrap();
    let drive = drivetrain::Model::new(model, &[1.0e4, 5.0e3], &[1.0e-3, 5.0e-4])
        .unwrap()
        .with_masses(masses)
        .unwrap();
    // Gravity pulls both links down (-z); about +y that is +x m g on the links, so the
    // drives hold u = -(x m g): u1 = -(0.5*2 + 1.25*1)*g, u2 = -(0.25*1)*g N m with the
    // default standard gravity g (-22.0725 and -2.4525 N m with g = 9.81).
    let g = STANDARD_GRAVITY;
    let c = drivetrain::step(
        &drive,
        &mut drivetrain::Data::new(&drive),
        &[0.0, 0.0],
        &Vector6::zeros(),
    )
    .unwrap();
    assert_relative_eq!(c.torque[0], -(0.5 * 2.0 + 1.25 * 1.0) * g, epsilon = 1e-12);
    assert_relative_eq!(c.torque[1], -(0.25 * 1.0) * g, epsilon = 1e-12);
    assert_eq!(&c.backlash_sign[..2], &[-1.0, -1.0]);
    // theta := theta - sgn(u) theta_b - u / K:
    // 0 + 1e-3 + (2.25 g)/1e4; 0 + 5e-4 + (0.25 g)/5e3 rad (3.20725e-3 and 9.905e-4 with
    // g = 9.81).
    assert_relative_eq!(
        c.q[0],
        1.0e-3 + (0.5 * 2.0 + 1.25 * 1.0) * g / 1.0e4,
        epsilon = 1e-15
    );
    assert_relative_eq!(c.q[1], 5.0e-4 + (0.25 * 1.0) * g / 5.0e3, epsilon = 1e-15);
}

/// Planar arm, joints about z (no gravity torque), pushing along +x: contact torques only.
#[test]
fn eq10_contact_hand_example() {
    let model = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .fixed(Isometry3::translation(0.5, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .fixed(Isometry3::translation(0.2, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let masses = LinkMasses::new()
        .with(1, 3.0, Vector3::new(0.2, 0.0, 0.0))
        .unwrap();
    let drive = drivetrain::Model::new(model, &[1000.0, 500.0, 200.0], &[1e-3, 2e-3, 0.0])
        .unwrap()
        .with_masses(masses)
        .unwrap();
    let q = [
        0.0,
        core::f64::consts::FRAC_PI_2,
        -core::f64::consts::FRAC_PI_2,
    ];
    // Joints at (0,0), (1,0), (1,0.5); TCP at (1.2, 0.5). J columns (v_x, v_y) = z x (p - o):
    // (-0.5, 1.2), (-0.5, 0.2), (0, 0.2). F = (10, 4): J^T F = [-5 + 4.8, -5 + 0.8, 0.8]
    // = [-0.2, -4.2, 0.8] N m.
    let w = Vector6::new(10.0, 4.0, 0.0, 0.0, 0.0, 0.0);
    let c = drivetrain::step(&drive, &mut drivetrain::Data::new(&drive), &q, &w).unwrap();
    for (u, e) in c.torque.iter().zip([-0.2, -4.2, 0.8]) {
        assert_relative_eq!(*u, e, epsilon = 1e-12);
    }
    // theta1 = 0 + 1e-3 + 0.2/1000 = 1.2e-3; theta2 = pi/2 + 2e-3 + 4.2/500 = pi/2 + 1.04e-2;
    // theta3 = -pi/2 - 0 - 0.8/200 = -pi/2 - 4e-3 (no backlash on joint 3).
    assert_relative_eq!(c.q[0], 1.2e-3, epsilon = 1e-15);
    assert_relative_eq!(c.q[1], q[1] + 1.04e-2, epsilon = 1e-15);
    assert_relative_eq!(c.q[2], q[2] - 4.0e-3, epsilon = 1e-15);
    // sgn(0) = 0: no force, no gravity about z -> the readings come back unchanged.
    let c0 = drivetrain::step(
        &drive,
        &mut drivetrain::Data::new(&drive),
        &q,
        &Vector6::zeros(),
    )
    .unwrap();
    assert_eq!(&c0.q[..3], &q);
    assert_eq!(&c0.backlash_sign[..3], &[0.0, 0.0, 0.0]);
    // A deadband keeps small torques from taking up backlash.
    let dead = drive.clone().with_torque_deadband(0.5).unwrap();
    let cd = drivetrain::step(&dead, &mut drivetrain::Data::new(&dead), &q, &w).unwrap();
    assert_eq!(&cd.backlash_sign[..3], &[0.0, -1.0, 1.0]);
}

/// 6R arm whose virtual joints are only about the joint axes.
fn spring_arm(k: &[f64; 6]) -> Model {
    let axes = fixtures::SIX_R_AXES;
    let offsets = [
        Vector3::new(0.3, 0.0, 0.6),
        Vector3::new(1.0, 0.0, 0.1),
        Vector3::new(0.9, 0.05, 0.0),
        Vector3::new(0.2, 0.0, 0.0),
        Vector3::new(0.15, 0.0, 0.0), // joint 6 on joint 4's axis at q5 = 0
        Vector3::new(0.1, 0.02, 0.1),
    ];
    let mut b = ModelBuilder::new();
    for ((axis, off), &ki) in axes.iter().zip(offsets).zip(k) {
        let mut ks = [f64::INFINITY; 3];
        ks[axis.iamax()] = ki;
        b = b
            .revolute(*axis)
            .unwrap()
            .spring(ks)
            .unwrap()
            .fixed(Isometry3::translation(off.x, off.y, off.z))
            .unwrap();
    }
    b.build().unwrap()
}

#[test]
fn cartesian_stiffness_inverts_the_joint_axis_compliance() {
    let k = [2.0e6, 1.5e6, 1.0e6, 4.0e5, 3.0e5, 2.0e5];
    let model = spring_arm(&k);
    let drive = drivetrain::Model::new(model.clone(), &k, &[0.0; 6]).unwrap();
    let mut data = drivetrain::Data::new(&drive);
    for q in [
        [0.1, -0.5, 0.9, 0.3, 0.7, -0.2],
        [-0.8, 0.2, 1.4, -1.0, -0.6, 0.5],
    ] {
        let kc = cartesian_stiffness(&drive, &mut data, &q).unwrap();
        let c = vjm::compliance(&model, &mut data.vjm, &q).unwrap();
        let kc_ref: Matrix6<f64> = c.try_inverse().unwrap();
        let err = (kc - kc_ref).norm() / kc_ref.norm();
        assert!(err < 1e-9, "relative error {err:e}");
        // and K C = I
        assert!((kc * c - Matrix6::identity()).norm() < 1e-8);
    }
    // Wrist singularity: joints 4 and 6 (both about x) collinear when joint 5 is at 0.
    let q = [0.1, -0.5, 0.9, 0.3, 0.0, -0.2];
    let e = cartesian_stiffness(&drive, &mut data, &q).unwrap_err();
    assert!(matches!(e, TickError::Singular { .. }), "{e:?}");
}

fn planar(lengths: &[f64], k: &[f64]) -> Model {
    let mut b = ModelBuilder::new();
    for (&l, &ki) in lengths.iter().zip(k) {
        b = b
            .revolute(Vector3::z())
            .unwrap()
            .spring([f64::INFINITY, f64::INFINITY, ki])
            .unwrap()
            .fixed(Isometry3::translation(l, 0.0, 0.0))
            .unwrap();
    }
    b.build().unwrap()
}

#[test]
fn planar_stiffness_matches_the_xy_compliance() {
    let k = [2000.0, 1000.0];
    let model = planar(&[0.5, 0.4], &k);
    let drive = drivetrain::Model::new(model.clone(), &k, &[0.0; 2]).unwrap();
    let mut data = drivetrain::Data::new(&drive);
    let q = [0.4, 1.3];
    let kxy = cartesian_stiffness_xy(&drive, &mut data, &q).unwrap();
    let c = vjm::compliance(&model, &mut data.vjm, &q).unwrap();
    let cxy = Matrix2::new(c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)]);
    assert!((kxy * cxy - Matrix2::identity()).norm() < 1e-10);
    // Stretched arm: singular.
    let e = cartesian_stiffness_xy(&drive, &mut data, &[0.4, 0.0]).unwrap_err();
    assert!(matches!(e, TickError::Singular { .. }));
    // Nearly stretched: refused by the condition limit, accepted with a looser one.
    let near = [0.4, 1e-7];
    assert!(cartesian_stiffness_xy(&drive, &mut data, &near).is_err());
    let loose = drive.clone().with_max_condition(1e9).unwrap();
    assert!(cartesian_stiffness_xy(&loose, &mut data, &near).is_ok());
    // Wrong joint count for the 6x6 and 3x3 forms.
    assert!(matches!(
        cartesian_stiffness(&drive, &mut data, &q),
        Err(TickError::WrongLength { .. })
    ));

    // 3R planar: [x, y, rz] stiffness inverts the matching compliance block; with the moment
    // free its xy part is the inverse of the xy compliance.
    let k3 = [3000.0, 1500.0, 400.0];
    let m3 = planar(&[0.5, 0.4, 0.15], &k3);
    let d3 = drivetrain::Model::new(m3.clone(), &k3, &[0.0; 3]).unwrap();
    let mut data3 = drivetrain::Data::new(&d3);
    let q3 = [0.3, 1.1, -0.7];
    let kp = cartesian_stiffness_planar(&d3, &mut data3, &q3).unwrap();
    let c = vjm::compliance(&m3, &mut data3.vjm, &q3).unwrap();
    let idx = [0usize, 1, 5];
    let cp = nalgebra::Matrix3::from_fn(|r, s| c[(idx[r], idx[s])]);
    assert!((kp * cp - nalgebra::Matrix3::identity()).norm() < 1e-9);
    let kxy = drivetrain::free_moment_xy(&kp).unwrap();
    let cxy = Matrix2::new(c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)]);
    assert!((kxy * cxy - Matrix2::identity()).norm() < 1e-9);
}

#[test]
fn bad_inputs_are_statuses() {
    let model = planar(&[0.5, 0.4], &[1.0, 1.0]);
    assert!(matches!(
        drivetrain::Model::new(model.clone(), &[1.0], &[0.0, 0.0]),
        Err(BuildError::WrongLength { .. })
    ));
    assert!(matches!(
        drivetrain::Model::new(model.clone(), &[1.0, 0.0], &[0.0, 0.0]),
        Err(BuildError::InvalidEntry {
            what: "stiffness",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        drivetrain::Model::new(model.clone(), &[1.0, f64::INFINITY], &[0.0, 0.0]),
        Err(BuildError::InvalidEntry {
            what: "stiffness",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        drivetrain::Model::new(model.clone(), &[1.0, 1.0], &[-1.0, 0.0]),
        Err(BuildError::InvalidEntry {
            what: "backlash",
            index: 0,
            ..
        })
    ));
    let mut m = LinkMasses::new();
    assert!(matches!(
        m.push(0, -1.0, Vector3::zeros()),
        Err(BuildError::InvalidEntry { what: "masses", .. })
    ));
    assert!(matches!(
        m.push(0, 1.0, Vector3::new(f64::NAN, 0.0, 0.0)),
        Err(BuildError::NonFinite {
            what: "centre of mass",
            ..
        })
    ));
    for _ in 0..deflect_core::vjm::MAX_MASSES {
        m.push(0, 1.0, Vector3::zeros()).unwrap();
    }
    assert!(matches!(
        m.push(0, 1.0, Vector3::zeros()),
        Err(BuildError::Capacity { what: "masses", .. })
    ));
    let far = LinkMasses::new().with(2, 1.0, Vector3::zeros()).unwrap();
    let drive = drivetrain::Model::new(model.clone(), &[1.0, 1.0], &[0.0, 0.0]).unwrap();
    // The mass hangs after joint 2, which the 2-joint chain does not have.
    assert!(matches!(
        drive.clone().with_masses(far),
        Err(BuildError::InvalidEntry {
            what: "masses (after_joint)",
            index: 0,
            value,
            ..
        }) if value == 2.0
    ));
    let mut data = drivetrain::Data::new(&drive);
    assert!(matches!(
        drivetrain::step(&drive, &mut data, &[0.0], &Vector6::zeros()),
        Err(TickError::WrongLength { .. })
    ));
    assert!(matches!(
        drivetrain::step(&drive, &mut data, &[0.0, f64::NAN], &Vector6::zeros()),
        Err(TickError::NonFinite { .. })
    ));
    let mut w = Vector6::zeros();
    w[3] = f64::INFINITY;
    assert!(matches!(
        drivetrain::step(&drive, &mut data, &[0.0, 0.1], &w),
        Err(TickError::NonFinite { .. })
    ));
    // A drive train of another model: the drive-train model now owns its chain, so the
    // mismatch left to catch is a workspace made for another model.
    let other = planar(&[0.5, 0.4, 0.1], &[1.0; 3]);
    let other_drive = drivetrain::Model::new(other, &[1.0; 3], &[0.0; 3]).unwrap();
    assert!(matches!(
        gravity_torques(&drive, &mut drivetrain::Data::new(&other_drive), &[0.0; 3]),
        Err(TickError::ModelMismatch {
            what: "dof",
            expected: 2,
            got: 3
        })
    ));
}

const URDF: &str = r#"<robot name="two_link">
  <link name="base"><inertial><origin xyz="0 0 0.1"/><mass value="50"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0.4 0 0"/><mass value="12"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="bracket"><inertial><origin xyz="0 0 0.05"/><mass value="2"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.3 0 0.01"/><mass value="6"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="tool"/>
  <joint name="a1" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="mount" type="fixed"><parent link="upper"/><child link="bracket"/>
    <origin xyz="0.8 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="a2" type="revolute"><parent link="bracket"/><child link="fore"/>
    <origin xyz="0 0 0.1" rpy="0 0 -1.5707963267948966"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="fore"/><child link="tool"/><origin xyz="0.6 0 0"/></joint>
</robot>"#;

const STIFFNESS: &str = r#"
[[virtual_joint]]
link = "upper"
k = [inf, 2.0e5, inf]

[[joint]]
name = "a2"
stiffness = 8.0e4
backlash = 2.0e-4

[[joint]]
name = "a1"
stiffness = 1.0e5   # N m/rad
"#;

#[test]
fn loads_stiffness_backlash_and_urdf_masses() {
    let robot = SerialRobot::from_str(URDF, STIFFNESS, None, "tool").unwrap();
    assert_eq!(robot.joint_names, ["a1", "a2"]);
    let drive = io::drive::from_str(&robot, URDF, STIFFNESS).unwrap();
    assert_eq!(drive.stiffness(), &[1.0e5, 8.0e4]);
    assert_eq!(drive.backlash(), &[0.0, 2.0e-4]);
    // The base (before a1) loads nothing; upper + bracket hang after a1 (bracket's CoM at
    // (0.8, 0, 0.05) in upper's frame), fore after a2.
    let m = drive.masses().as_slice();
    assert_eq!(m.len(), 2);
    assert_eq!((m[0].after_joint, m[1].after_joint), (0, 1));
    assert_relative_eq!(m[0].mass, 14.0);
    assert_relative_eq!(
        m[0].com,
        (Vector3::new(0.4, 0.0, 0.0) * 12.0 + Vector3::new(0.8, 0.0, 0.05) * 2.0) / 14.0,
        epsilon = 1e-12
    );
    assert_relative_eq!(m[1].com, Vector3::new(0.3, 0.0, 0.01), epsilon = 1e-12);
    // Against the hand-built table on the same model.
    let by_hand = LinkMasses::new()
        .with(0, 12.0, Vector3::new(0.4, 0.0, 0.0))
        .unwrap()
        .with(0, 2.0, Vector3::new(0.8, 0.0, 0.05))
        .unwrap()
        .with(1, 6.0, Vector3::new(0.3, 0.0, 0.01))
        .unwrap();
    let hand = drivetrain::Model::new(robot.model.clone(), &[1.0e5, 8.0e4], &[0.0, 2.0e-4])
        .unwrap()
        .with_masses(by_hand)
        .unwrap();
    let mut data = drivetrain::Data::new(&drive);
    let mut hand_data = drivetrain::Data::new(&hand);
    for q in [[0.0, 0.0], [0.4, -1.1]] {
        let a = gravity_torques(&drive, &mut data, &q).unwrap();
        let b = gravity_torques(&hand, &mut hand_data, &q).unwrap();
        for j in 0..2 {
            assert_relative_eq!(a[j], b[j], epsilon = 1e-9);
        }
    }
    // At q = 0 the CoMs sit at x = 0.4 (upper), 0.8 (bracket) and 0.8 + 0.3 (fore) from a1:
    // the drive holds -(sum x m) g = -(4.8 + 1.6 + 6.6) * g N m (default standard gravity).
    let a = gravity_torques(&drive, &mut data, &[0.0, 0.0]).unwrap();
    assert_relative_eq!(a[0], -(4.8 + 1.6 + 6.6) * STANDARD_GRAVITY, epsilon = 1e-9);
    assert_relative_eq!(a[1], -(0.3 * 6.0) * STANDARD_GRAVITY, epsilon = 1e-9);
}

#[test]
fn drive_file_errors_name_the_entry() {
    let robot = SerialRobot::from_str(URDF, STIFFNESS, None, "tool").unwrap();
    let cases = [
        ("[[joint]]\nname = \"a1\"\nstiffness = 1.0\n", "a2"),
        (
            "[[joint]]\nname = \"a1\"\nstiffness = 1.0\n[[joint]]\nname = \"a1\"\nstiffness = 2.0\n",
            // The duplicate entry is a `LoadError::DuplicateName` ("duplicate ... 'a1'").
            "duplicate",
        ),
        ("[[joint]]\nname = \"mount\"\nstiffness = 1.0\n", "mount"),
        ("[[joint]]\nname = \"a1\"\nstiffness = -1.0\n", "a1"),
        (
            "[[joint]]\nname = \"a1\"\nstiffness = 1.0\nbacklash = -0.1\n",
            "backlash",
        ),
        ("[[joint]]\nname = \"a1\"\nstifness = 1.0\n", "stifness"),
    ];
    for (text, needle) in cases {
        let e = io::drive::from_str(&robot, URDF, text)
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{e} should mention {needle}");
    }
    assert_eq!(io::drive::parse(STIFFNESS).unwrap().len(), 2);
}
