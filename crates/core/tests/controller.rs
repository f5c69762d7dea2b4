//! The controller conventions and configuration words against their published definitions,
//! on poses of the KR 300 derived by hand (its URDF: A2 at (0.35, 0, 0.675), A3 1.15 m along
//! the lower arm, the wrist point 1.0 m along the upper arm and 0.041 m below it; planar arm
//! at A1 = 0, the wrist point `W = (0.35, 0, 0.675) + Ry(a2) (1.15, 0, 0) + Ry(a2 + a3) (1.0, 0,
//! -0.041)`).
//!
//! KUKA (KSS manuals): S bit 0 overhead (the wrist's x < 0 in the A1 frame), bit 1 `A3 >= phi`
//! (wrist in front of the line A2-A3), bit 2 `A5 <= 0`; T bit i for `A(i+1) < 0`. ABB
//! (RAPID reference, `confdata`): `cf1, cf4, cf6 = floor(axis / 90 deg)`, `cfx = 4 behind axis
//! 1 + 2 behind the lower arm + 1 axis 5 negative`.

use std::f64::consts::{FRAC_PI_2, PI};

use deflect_core::SerialRobot;
use deflect_core::controller::{self, Convention, Vendor};
use deflect_core::vjm::{self, Data};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

fn kr300() -> SerialRobot {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/kr300/");
    SerialRobot::from_path(
        format!("{dir}kr300_r2500.urdf"),
        format!("{dir}kr300_r2500_stiffness.toml"),
        "tcp",
    )
    .unwrap()
}

/// The URDF joints of KUKA axis values in degrees (A1 = -a1, A4 = -a4, A6 = -a6).
fn from_kuka(a: [f64; 6]) -> [f64; 6] {
    let r = |d: f64| d.to_radians();
    [-r(a[0]), r(a[1]), r(a[2]), -r(a[3]), r(a[4]), -r(a[5])]
}

fn st(robot: &SerialRobot, a_deg: [f64; 6]) -> (u8, u8) {
    let c = robot.controller.as_ref().unwrap();
    let mut data = Data::new(&robot.model);
    controller::kuka_status_turn(&robot.model, &mut data, &from_kuka(a_deg), c).unwrap()
}

#[test]
fn the_kr300_file_carries_kukas_convention_and_its_tool_frame() {
    let robot = kr300();
    let c = robot.controller.unwrap();
    assert_eq!(c.vendor, Vendor::Kuka);
    assert_eq!(&c.sign[..6], &[-1.0, 1.0, 1.0, -1.0, 1.0, -1.0]);
    // TCP in the flange (ft_sensor) frame, by hand: spindle 0.06 up z, tool mount 0.25 further
    // and turned Ry(90 deg), the TCP 0.12 along that mount's z: (0.12, 0, 0.31), Ry(90 deg).
    let t = c.tool;
    assert!((t.translation.vector - Vector3::new(0.12, 0.0, 0.31)).norm() < 1e-12);
    let ry = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), FRAC_PI_2);
    assert!(t.rotation.angle_to(&ry) < 1e-12);
    // The flange frame times the tool frame is the TCP, at any joints.
    let q = from_kuka([20.0, -70.0, 100.0, 30.0, 40.0, -50.0]);
    let mut data = Data::new(&robot.model);
    vjm::joint_jacobian(&robot.model, &mut data, &q).unwrap();
    let flange = data.tcp * t.inverse();
    // The flange's z is A6's axis (the URDF's link_6 x) and its origin 0.24 + 0.03 m past A5.
    let (o5, _) = data.joint_axis(4).unwrap();
    let (_, u6) = data.joint_axis(5).unwrap();
    assert!((flange.rotation * Vector3::z() - u6).norm() < 1e-12);
    assert!((flange.translation.vector - o5 - u6 * 0.27).norm() < 1e-12);
}

#[test]
fn kuka_status_of_each_octant_by_hand() {
    let robot = kr300();
    // (KUKA axes in degrees, S, T), each worked out in the module docs' planar formula:
    let cases: [([f64; 6], u8, u8); 8] = [
        // Mastering arm (A2 -90 upright, A3 +90 level): W = (1.35, 0, 1.784), basic; A3 =
        // 90 >= phi: front; A5 = +30 > 0. T: A2 < 0.
        ([0.0, -90.0, 90.0, 0.0, 30.0, 0.0], 2, 2),
        // ... A5 = -30: bit 2; T gains A5 (16).
        ([0.0, -90.0, 90.0, 0.0, -30.0, 0.0], 6, 18),
        // A2 -20, A3 -60: the forearm at -80 deg, W = (1.645, 0, 2.046): basic, but A3 < phi
        // (W behind the lower arm's line: (d x v) . y = -0.846): bit 1 clear. T: A2, A3.
        ([0.0, -20.0, -60.0, 0.0, 30.0, 0.0], 0, 6),
        ([0.0, -20.0, -60.0, 0.0, -30.0, 0.0], 4, 22),
        // A2 -138, A3 +40: lower arm leaning back, the forearm at -98 deg, W x = 0.35 - 0.855
        // - 0.10 < 0: overhead; A3 >= phi: front.
        ([0.0, -138.0, 40.0, 0.0, 30.0, 0.0], 3, 2),
        ([0.0, -138.0, 40.0, 0.0, -30.0, 0.0], 7, 18),
        // A2 -138, A3 -40: the forearm pointing back (-178 deg), W x = -1.5: overhead, behind.
        ([0.0, -138.0, -40.0, 0.0, 30.0, 0.0], 1, 6),
        ([0.0, -138.0, -40.0, 0.0, -30.0, 0.0], 5, 22),
    ];
    for (a, s, t) in cases {
        assert_eq!(st(&robot, a), (s, t), "{a:?}");
        // The A1 coordinate system turns with A1: S is the same at A1 = 120 and at -75
        // (T gains bit 0 for the negative A1).
        let mut turned = a;
        turned[0] = 120.0;
        assert_eq!(st(&robot, turned), (s, t), "{turned:?}");
        turned[0] = -75.0;
        assert_eq!(st(&robot, turned), (s, t | 1), "{turned:?}");
    }
}

#[test]
fn kuka_bit_1_turns_at_phi_and_the_wrist_flip_turns_bit_2() {
    let robot = kr300();
    // phi: the forearm's wrist point on the lower arm's line, -sin(b) - 0.041 cos(b) = 0.
    let phi = (-0.041f64).atan2(1.0).to_degrees();
    let at = |a3: f64| st(&robot, [0.0, -45.0, a3, 0.0, 30.0, 0.0]).0 & 2;
    assert_eq!(at(phi + 1e-6), 2);
    assert_eq!(at(phi - 1e-6), 0);
    // The flipped wrist (A4 + 180, A5 -> -A5, A6 + 180) reaches the same flange pose: same
    // position and orientation, the other status bit 2 and turn bits.
    let a = [10.0, -60.0, 80.0, 20.0, 35.0, 40.0];
    let flipped = [10.0, -60.0, 80.0, 20.0 - 180.0, -35.0, 40.0 - 180.0];
    let mut data = Data::new(&robot.model);
    let p = vjm::forward(&robot.model, &mut data, &from_kuka(a)).unwrap();
    let pf = vjm::forward(&robot.model, &mut data, &from_kuka(flipped)).unwrap();
    assert!((p.translation.vector - pf.translation.vector).norm() < 1e-12);
    assert!(p.rotation.angle_to(&pf.rotation) < 1e-12);
    assert_eq!(st(&robot, a), (2, 2));
    // Flipped: A4, A5, A6 < 0 join A2 in T.
    assert_eq!(st(&robot, flipped), (6, 2 | 8 | 16 | 32));
}

/// An ABB-style convention on the KR 300's geometry: ABB's axis 2 reads 0 upright (the URDF's
/// -90 deg) and axis 3 reads 0 level at that (the URDF's +90 deg); the axes turn as the URDF's.
fn abb(robot: &SerialRobot) -> Convention {
    Convention::new(
        Vendor::Abb,
        &robot.model,
        &[1.0; 6],
        &[0.0, FRAC_PI_2, -FRAC_PI_2, 0.0, 0.0, 0.0],
        Isometry3::identity(),
        Isometry3::identity(),
    )
    .unwrap()
}

fn conf(robot: &SerialRobot, c: &Convention, abb_deg: [f64; 6]) -> [i32; 4] {
    let q: Vec<f64> = abb_deg
        .iter()
        .zip(&c.offset)
        .map(|(a, o)| a.to_radians() - o)
        .collect();
    let mut data = Data::new(&robot.model);
    controller::abb_confdata(&robot.model, &mut data, &q, c).unwrap()
}

#[test]
fn abb_confdata_of_each_configuration_by_hand() {
    let robot = kr300();
    let c = abb(&robot);
    // The KUKA cases above in ABB's axes (axis 2 = A2 + 90, axis 3 = A3 - 90): the same
    // geometry, cfx = 4 behind axis 1 + 2 behind the lower arm + 1 axis 5 negative.
    let cases: [([f64; 6], i32); 8] = [
        ([0.0, 0.0, 0.0, 0.0, 30.0, 0.0], 0),
        ([0.0, 0.0, 0.0, 0.0, -30.0, 0.0], 1),
        ([0.0, 70.0, -150.0, 0.0, 30.0, 0.0], 2),
        ([0.0, 70.0, -150.0, 0.0, -30.0, 0.0], 3),
        ([0.0, -48.0, -50.0, 0.0, 30.0, 0.0], 4),
        ([0.0, -48.0, -50.0, 0.0, -30.0, 0.0], 5),
        ([0.0, -48.0, -130.0, 0.0, 30.0, 0.0], 6),
        ([0.0, -48.0, -130.0, 0.0, -30.0, 0.0], 7),
    ];
    for (a, cfx) in cases {
        assert_eq!(conf(&robot, &c, a), [0, 0, 0, cfx], "{a:?}");
    }
    // Quadrants: [0, 90) is 0, [90, 180) 1, [-90, 0) -1, [-180, -90) -2, past a turn on.
    let q = conf(&robot, &c, [100.0, 0.0, 0.0, 200.0, 30.0, -270.5]);
    assert_eq!(q, [1, 2, -4, 0]);
    let q = conf(&robot, &c, [-10.0, 0.0, 0.0, -100.0, 30.0, 89.9]);
    assert_eq!(q, [-1, -2, 0, 0]);
    assert_eq!(controller::abb_quadrant(0.0), 0);
    assert_eq!(controller::abb_quadrant(-1e-12), -1);
    assert_eq!(controller::abb_quadrant(PI / 2.0), 1);
}

#[test]
fn conventions_refuse_what_they_cannot_mean() {
    let robot = kr300();
    let m = &robot.model;
    let id = Isometry3::identity();
    let bad_sign = Convention::new(
        Vendor::Kuka,
        m,
        &[1.0, 1.0, 0.5, 1.0, 1.0, 1.0],
        &[0.0; 6],
        id,
        id,
    );
    assert!(format!("{}", bad_sign.unwrap_err()).contains("sign"));
    let short = Convention::new(Vendor::Abb, m, &[1.0; 5], &[0.0; 6], id, id);
    assert!(format!("{}", short.unwrap_err()).contains("sign"));
    let nan = Convention::new(
        Vendor::Kuka,
        m,
        &[1.0; 6],
        &[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0],
        id,
        id,
    );
    assert!(format!("{}", nan.unwrap_err()).contains("offset"));
    let far = Isometry3::from_parts(
        Translation3::new(f64::INFINITY, 0.0, 0.0),
        UnitQuaternion::identity(),
    );
    assert!(Convention::new(Vendor::UniversalRobots, m, &[1.0; 6], &[0.0; 6], far, id).is_err());
    // Round trip of the axis values.
    let c = robot.controller.unwrap();
    let q = [0.1, -0.2, 0.3, -0.4, 0.5, -0.6];
    let back = c.from_controller(&c.to_controller(&q));
    assert!(back.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-15));
}
