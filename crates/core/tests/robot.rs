//! URDF + stiffness TOML loading: the validation urdf-rs leaves to its users.

use approx::assert_relative_eq;
use deflect_core::vjm::{self, Data, Vector6};
use deflect_core::{LoadError, SerialRobot};

/// A 2R planar arm: base -> j1 (z) -> l1 -> j2 (z, 0.5 m out) -> l2 -> fixed 0.3 m -> tip.
fn urdf(j2_origin: &str, j2_axis: &str, extra: &str) -> String {
    format!(
        r#"<robot name="two_r">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="tip"/>{extra}
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin {j2_origin}/><axis xyz="{j2_axis}"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="fix" type="fixed"><parent link="l2"/><child link="tip"/>
    <origin xyz="0.3 0 0" rpy="0 0 0"/></joint>
</robot>"#
    )
}

fn good_urdf() -> String {
    urdf(r#"xyz="0.5 0 0" rpy="0 0 0""#, "0 0 1", "")
}

const STIFF: &str = r#"
[[virtual_joint]]
link = "l1"
k = [inf, inf, 1.0e4]

[[virtual_joint]]
link = "l2"
xyz = [0.1, 0.0, 0.0]
k = [inf, inf, 2.0e3]
"#;

#[test]
fn loads_and_matches_hand_computation() {
    let r = SerialRobot::from_str(&good_urdf(), STIFF, None, "tip").unwrap();
    assert_eq!(r.joint_names, ["j1", "j2"]);
    assert_eq!(r.spring_names, ["l1", "l2"]);
    assert_eq!(r.base_link, "base");
    assert_eq!(r.joint_limits, [(-3.0, 3.0), (-2.0, 2.0)]);
    let m = &r.model;
    let mut data = Data::new(m);
    let t = vjm::forward(m, &mut data, &[0.0, 0.0]).unwrap();
    assert_relative_eq!(t.translation.vector.x, 0.8, epsilon = 1e-15);
    assert_relative_eq!(t.translation.vector.z, 0.1, epsilon = 1e-15);
    // Fy = 100 N at the stretched tip: spring 1 at 0.8 m, spring 2 at 0.2 m from the TCP.
    let c = vjm::compliance(m, &mut data, &[0.0, 0.0]).unwrap();
    assert_relative_eq!(
        c[(1, 1)],
        0.8 * 0.8 / 1.0e4 + 0.2 * 0.2 / 2.0e3,
        epsilon = 1e-18
    );
    let d = vjm::deflection(
        m,
        &mut data,
        &[0.0, 0.0],
        &Vector6::new(0.0, 100.0, 0.0, 0.0, 0.0, 0.0),
        vjm::Load::Exact,
    )
    .unwrap();
    assert_relative_eq!(d[5], 80.0 / 1.0e4 + 20.0 / 2.0e3, epsilon = 1e-15);
}

#[test]
fn several_springs_on_one_link_apply_in_file_order() {
    let two = r#"
[[virtual_joint]]
link = "l2"
k = [inf, inf, 1.0e3]
[[virtual_joint]]
link = "l2"
xyz = [0.3, 0.0, 0.0]
rpy = [0.0, 0.0, 0.0]
k = [inf, inf, 4.0e3]
"#;
    let r = SerialRobot::from_str(&good_urdf(), two, None, "tip").unwrap();
    assert_eq!(r.spring_names, ["l2", "l2#1"]);
    let mut data = Data::new(&r.model);
    let c = vjm::compliance(&r.model, &mut data, &[0.0, 0.0]).unwrap();
    // The second spring sits at the TCP: it adds rotation only.
    assert_relative_eq!(c[(1, 1)], 0.09 / 1.0e3, epsilon = 1e-18);
    assert_relative_eq!(c[(5, 5)], 1.0 / 1.0e3 + 1.0 / 4.0e3, epsilon = 1e-18);
}

fn err(urdf: &str, stiff: &str, tip: &str) -> LoadError {
    SerialRobot::from_str(urdf, stiff, None, tip).unwrap_err()
}

#[test]
fn every_malformed_input_is_a_named_error() {
    let nan = urdf(r#"xyz="NaN 0 0" rpy="0 0 0""#, "0 0 1", "");
    assert_eq!(
        err(&nan, STIFF, "tip"),
        LoadError::NonFiniteOrigin {
            element: "joint 'j2'".into()
        }
    );
    let inf = urdf(r#"xyz="0.5 0 0" rpy="0 inf 0""#, "0 0 1", "");
    assert!(matches!(
        err(&inf, STIFF, "tip"),
        LoadError::NonFiniteOrigin { .. }
    ));
    let zero = urdf(r#"xyz="0.5 0 0" rpy="0 0 0""#, "0 0 0", "");
    assert_eq!(
        err(&zero, STIFF, "tip"),
        LoadError::ZeroAxis { joint: "j2".into() }
    );
    assert_eq!(
        err(&good_urdf(), STIFF, "nowhere"),
        LoadError::UnknownLink {
            link: "nowhere".into(),
            referenced_by: "tip_link".into()
        }
    );
    // A second tree: the URDF has two roots (the specification asks for one), refused
    // naming both, whichever link the chain would use.
    let island = urdf(
        r#"xyz="0.5 0 0" rpy="0 0 0""#,
        "0 0 1",
        r#"<link name="other_root"/><link name="island"/>
  <joint name="k" type="fixed"><parent link="other_root"/><child link="island"/></joint>"#,
    );
    for tip in ["island", "tip"] {
        assert!(matches!(
            SerialRobot::from_str(&island, STIFF, Some("base"), tip).unwrap_err(),
            LoadError::InvalidValue { field: "root links", ref got, .. }
                if got.contains("'base', 'other_root'")
        ));
    }
    // One tree, a tip that is not below the base.
    assert_eq!(
        SerialRobot::from_str(&good_urdf(), STIFF, Some("tip"), "base").unwrap_err(),
        LoadError::TipNotReachable {
            tip: "base".into(),
            base: "tip".into()
        }
    );
    let dup_link = urdf(
        r#"xyz="0.5 0 0" rpy="0 0 0""#,
        "0 0 1",
        r#"<link name="l1"/>"#,
    );
    assert_eq!(
        err(&dup_link, STIFF, "tip"),
        LoadError::DuplicateName {
            kind: "link",
            name: "l1".into()
        }
    );
    let dup_joint = good_urdf().replace(r#"name="fix""#, r#"name="j1""#);
    assert_eq!(
        err(&dup_joint, STIFF, "tip"),
        LoadError::DuplicateName {
            kind: "joint",
            name: "j1".into()
        }
    );
    let missing_child = good_urdf().replace(r#"<child link="tip"/>"#, r#"<child link="ghost"/>"#);
    assert_eq!(
        err(&missing_child, STIFF, "l2"),
        LoadError::UnknownLink {
            link: "ghost".into(),
            referenced_by: "joint 'fix'".into()
        }
    );
    let cycle = good_urdf().replace(
        r#"<joint name="j1" type="revolute"><parent link="base"/>"#,
        r#"<joint name="j1" type="revolute"><parent link="tip"/>"#,
    );
    assert!(matches!(
        err(&cycle, STIFF, "tip"),
        LoadError::NotATree { .. }
    ));
    let bad_limit = good_urdf().replace(r#"lower="-2" upper="2""#, r#"lower="2" upper="-2""#);
    assert_eq!(
        err(&bad_limit, STIFF, "tip"),
        LoadError::InvalidLimit {
            joint: "j2".into(),
            lower: 2.0,
            upper: -2.0
        }
    );
    let floating = good_urdf().replace(
        r#"name="j2" type="revolute""#,
        r#"name="j2" type="floating""#,
    );
    assert_eq!(
        err(&floating, STIFF, "tip"),
        LoadError::UnsupportedJoint {
            joint: "j2".into(),
            kind: "floating".into()
        }
    );
    assert!(matches!(
        err("<robot name='x'><link", STIFF, "tip"),
        LoadError::UrdfParse { .. }
    ));
}

#[test]
fn stiffness_file_errors_name_the_entry() {
    let u = good_urdf();
    let unknown = "[[virtual_joint]]\nlink = \"elbow\"\nk = [1.0, 1.0, 1.0]\n";
    assert_eq!(
        err(&u, unknown, "tip"),
        LoadError::UnknownLink {
            link: "elbow".into(),
            referenced_by: "virtual_joint #0 of the stiffness file".into()
        }
    );
    let off_chain = "[[virtual_joint]]\nlink = \"tip\"\nk = [1.0, 1.0, 1.0]\n";
    assert_eq!(
        err(&u, off_chain, "l2"),
        LoadError::LinkNotInChain { link: "tip".into() }
    );
    let negative = "[[virtual_joint]]\nlink = \"l1\"\nk = [1.0, 1.0, 1.0]\n\
                    [[virtual_joint]]\nlink = \"l2\"\nk = [1.0, 0.0, 1.0]\n";
    let e = err(&u, negative, "tip");
    assert_eq!(
        e,
        LoadError::NonPositiveStiffness {
            element: "virtual_joint #1 on link 'l2'".into(),
            axis: 1,
            value: 0.0
        }
    );
    assert!(
        e.to_string().contains("virtual_joint #1 on link 'l2'"),
        "{e}"
    );
    let nan = "[[virtual_joint]]\nlink = \"l1\"\nk = [nan, 1.0, 1.0]\n";
    assert!(matches!(
        err(&u, nan, "tip"),
        LoadError::NonPositiveStiffness { axis: 0, .. }
    ));
    let bad_xyz = "[[virtual_joint]]\nlink = \"l1\"\nxyz = [inf, 0.0, 0.0]\nk = [1.0, 1.0, 1.0]\n";
    assert!(matches!(
        err(&u, bad_xyz, "tip"),
        LoadError::NonFiniteOrigin { .. }
    ));
    // Unknown keys, wrong arity and syntax errors come from the TOML parser with a location.
    for bad in [
        "[[virtual_joint]]\nlink = \"l1\"\nstiffness = [1.0, 1.0, 1.0]\n",
        "[[virtual_joint]]\nlink = \"l1\"\nk = [1.0, 1.0]\n",
        "[[virtual_joint]\nlink = \"l1\"\n",
    ] {
        match err(&u, bad, "tip") {
            LoadError::StiffnessParse { message } => assert!(message.contains("line"), "{message}"),
            other => panic!("expected StiffnessParse, got {other:?}"),
        }
    }
    let missing =
        SerialRobot::from_path("/nonexistent.urdf", "/nonexistent.toml", "tip").unwrap_err();
    assert!(matches!(missing, LoadError::Io { ref path, .. } if path == "/nonexistent.urdf"));
}

#[test]
fn a_spring_at_a_joint_has_its_first_axis_along_the_joint_axis() {
    // Joint j2 about z: `joint = "j2"` puts the spring in l2's frame with x along z, i.e.
    // the same spring as `link = "l2"` with the torsional stiffness about z written last.
    // Check it through the compliance: both files give identical models.
    let u = good_urdf();
    let by_joint = "[[virtual_joint]]\njoint = \"j2\"\nk = [2.0e3, 5.0e4, 7.0e4]\n";
    let by_link = "[[virtual_joint]]\nlink = \"l2\"\nrpy = [0.0, -1.5707963267948966, 0.0]\n\
                   k = [2.0e3, 5.0e4, 7.0e4]\n";
    let a = SerialRobot::from_str(&u, by_joint, None, "tip").unwrap();
    let b = SerialRobot::from_str(&u, by_link, None, "tip").unwrap();
    assert_eq!(a.spring_names, ["j2"]);
    let q = [0.3, -0.7];
    let (mut da, mut db) = (Data::new(&a.model), Data::new(&b.model));
    let ca = vjm::compliance(&a.model, &mut da, &q).unwrap();
    let cb = vjm::compliance(&b.model, &mut db, &q).unwrap();
    // 1/k_torsion about z: a 100 N force normal to the last 0.3 m turns it by 30/2000 rad.
    let w = Vector6::new(0.0, 100.0, 0.0, 0.0, 0.0, 0.0);
    let d = vjm::deflection(&a.model, &mut da, &[0.0, 0.0], &w, vjm::Load::Exact).unwrap();
    assert_relative_eq!(d[5], 100.0 * 0.3 / 2.0e3, max_relative = 1e-4);
    for (x, y) in ca.iter().zip(cb.iter()) {
        assert_relative_eq!(*x, *y, epsilon = 1e-18, max_relative = 1e-12);
    }
    // A joint about -x gets a half turn about z (x -> -x), still x along the axis.
    let neg = urdf(r#"xyz="0.5 0 0" rpy="0 0 0""#, "-1 0 0", "");
    assert!(SerialRobot::from_str(&neg, by_joint, None, "tip").is_ok());
}

#[test]
fn spring_placement_errors_are_named() {
    let u = good_urdf();
    let cases = [
        ("[[virtual_joint]]\nk = [1.0, 1.0, 1.0]\n", "exactly one of"),
        (
            "[[virtual_joint]]\nlink = \"l1\"\njoint = \"j1\"\nk = [1.0, 1.0, 1.0]\n",
            "not both",
        ),
        (
            "[[virtual_joint]]\njoint = \"j1\"\nxyz = [0.0, 0.0, 0.1]\nk = [1.0, 1.0, 1.0]\n",
            "only with `link`",
        ),
        (
            "[[virtual_joint]]\njoint = \"nope\"\nk = [1.0, 1.0, 1.0]\n",
            "unknown joint 'nope'",
        ),
        (
            "[[virtual_joint]]\njoint = \"fix\"\nk = [1.0, 1.0, 1.0]\n",
            "fixed",
        ),
        (
            "[[virtual_joint]]\njoint = \"j2\"\nk = [1.0, 0.0, 1.0]\n",
            "virtual_joint #0 at joint 'j2': stiffness about y",
        ),
        (
            "[[virtual_joint]]\njoint = \"j2\"\nk = [1.0, 1.0]\n",
            "expected 3 values",
        ),
    ];
    for (toml, needle) in cases {
        let e = err(&u, toml, "tip").to_string();
        assert!(e.contains(needle), "{toml:?}: {e}");
    }
    // A joint off the chain (tip = l1 leaves j2 out).
    let e = err(
        &u,
        "[[virtual_joint]]\njoint = \"j2\"\nk = [1.0, 1.0, 1.0]\n",
        "l1",
    )
    .to_string();
    assert!(e.contains("not on the base-to-tip chain"), "{e}");
}
