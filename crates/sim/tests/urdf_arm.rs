//! The testbed arm built from a URDF and a stiffness file: its rigid TCP is deflect-core's
//! forward kinematics, and its static compliance at small loads is deflect-core's
//! linearized `J K^-1 J^T`.

use deflect_core::vjm::{self, Data, Vector6};
use deflect_sim::urdf_arm::{FlexSerialArm, ServoParams, arm_spec};

fn read(rel: &str) -> String {
    std::fs::read_to_string(format!("{}/../../{rel}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn kr300() -> deflect_sim::urdf_arm::ArmSpec {
    arm_spec(
        &read("robots/kr300/kr300_r2500.urdf"),
        &read("robots/kr300/kr300_r2500_stiffness.toml"),
        None,
        "tcp",
    )
    .unwrap()
}

const Q0: [f64; 6] = [0.3, -0.9, 1.4, 0.2, 1.0708, -0.4];

#[test]
fn rigid_tcp_is_the_library_forward_kinematics() {
    let spec = kr300();
    let arm = FlexSerialArm::new(&spec, &Q0, None, &ServoParams::default(), 1.0).unwrap();
    let model = &spec.robot.model;
    let want = vjm::forward(model, &mut Data::new(model), &Q0).unwrap();
    let got = arm.tcp_pose();
    assert!((got.translation.vector - want.translation.vector).norm() < 1e-12);
    assert!(got.rotation.angle_to(&want.rotation) < 1e-12);
    // 6 joints and the 10 finite virtual joints of Table 1 (the tool's is rigid).
    assert_eq!(arm.body_count(), 16);
}

#[test]
fn static_compliance_matches_j_kinv_jt() {
    let spec = kr300();
    let model = &spec.robot.model;
    let c = vjm::compliance(model, &mut Data::new(model), &Q0).unwrap();
    for (i, w) in [
        Vector6::new(100.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        Vector6::new(0.0, -100.0, 0.0, 0.0, 0.0, 0.0),
        Vector6::new(0.0, 0.0, 100.0, 0.0, 0.0, 0.0),
        Vector6::new(0.0, 0.0, 0.0, 20.0, 0.0, 0.0),
        Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, -20.0),
    ]
    .iter()
    .enumerate()
    {
        let mut arm = FlexSerialArm::new(&spec, &Q0, None, &ServoParams::default(), 1.0).unwrap();
        let d = arm.static_deflection(w, 5_000);
        let want = c * w;
        let err = (d - want).norm() / want.norm();
        assert!(err < 1e-2, "load {i}: relative error {err}");
    }
}

/// deflect's SCARA: a prismatic quill among three revolutes, the task it controls position
/// and spin.
fn scara() -> deflect_sim::urdf_arm::ArmSpec {
    arm_spec(
        &read("robots/scara/scara4.urdf"),
        &read("robots/scara/scara4_stiffness.toml"),
        None,
        "tcp",
    )
    .unwrap()
}

#[test]
fn a_prismatic_quill_is_built_at_its_stroke_and_bends_as_the_model() {
    let spec = scara();
    let q0 = [0.4, -1.1, 0.08, 0.3];
    let arm = FlexSerialArm::new(&spec, &q0, None, &ServoParams::default(), 30.0).unwrap();
    let model = &spec.robot.model;
    let want = vjm::forward(model, &mut Data::new(model), &q0).unwrap();
    let got = arm.tcp_pose();
    assert!((got.translation.vector - want.translation.vector).norm() < 1e-12);
    assert!(got.rotation.angle_to(&want.rotation) < 1e-12);
    // The quill 0.08 m down its stroke: 0.2 m up, 0.05 to the flange and 0.05 to the TCP.
    assert!((want.translation.vector.z - (0.2 - 0.08 - 0.1)).abs() < 1e-12);
    // 4 joints and their 4 springs; the link-side quill reads its stroke in metres.
    assert_eq!(arm.body_count(), 8);
    let (q, _) = arm.joint_state();
    assert!((q[2] - 0.08).abs() < 1e-12, "{q:?}");
    let c = vjm::compliance(model, &mut Data::new(model), &q0).unwrap();
    for w in [
        Vector6::new(50.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        Vector6::new(0.0, 50.0, 0.0, 0.0, 0.0, 0.0),
        Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 5.0),
    ] {
        let mut arm = FlexSerialArm::new(&spec, &q0, None, &ServoParams::default(), 30.0).unwrap();
        let d = arm.static_deflection(&w, 20_000);
        let want = c * w;
        let err = (d - want).norm() / want.norm();
        assert!(
            err < 2e-2,
            "{w:?}: relative error {err}, {d:?} against {want:?}"
        );
    }
    // Commanded down the stroke, the quill follows (the servo of a linear axis).
    let mut arm = FlexSerialArm::new(&spec, &q0, None, &ServoParams::default(), 1.0).unwrap();
    for _ in 0..2000 {
        arm.step_servo(&[0.4, -1.1, 0.1, 0.3], &[0.0; 4], &[0.0; 4], None);
    }
    let (q, _) = arm.joint_state();
    assert!((q[2] - 0.1).abs() < 1e-6, "{q:?}");
}
