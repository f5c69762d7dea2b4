//! Deflection under the arm's own inertia (`vjm::deflection_under`): hand-derived loads,
//! agreement with the payload formula for a mass at the TCP, the acceleration bias against
//! finite differences of the forward kinematics, and the linearized model's order.

use deflect_core::dalembert::serial::Payload;
use deflect_core::motion::PoseState;
use deflect_core::vjm::{self, ArmMotion, Data, Vector6};
use deflect_core::{ModelBuilder, TickError};
use nalgebra::{Isometry3, Matrix3, Vector3};

mod fixtures;

const INF: f64 = f64::INFINITY;

/// A 1 m link about z, soft about z at the joint (k), with a point mass m at its tip plus a
/// rotational inertia `izz` about its centre.
fn one_link(k: f64, m: f64, izz: f64) -> vjm::Model {
    ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([INF, INF, k])
        .unwrap()
        .mass(
            m,
            Vector3::new(1.0, 0.0, 0.0),
            Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, izz)),
        )
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap()
}

#[test]
fn a_swinging_mass_loads_the_spring_with_m_l2_qdd() {
    let (k, m, izz) = (1.0e4, 20.0, 0.5);
    let model = one_link(k, m, izz);
    let mut data = Data::new(&model);
    let (qd, qdd) = ([3.0], [-40.0]);
    let motion = ArmMotion {
        qd: &qd,
        qdd: &qdd,
        gravity: Vector3::zeros(),
    };
    let d = vjm::deflection(
        &model,
        &mut data,
        &[0.2],
        &Vector6::zeros(),
        vjm::Load::ExactWithArm(motion),
    )
    .unwrap();
    // Tangential inertial force -m L qdd at L, the centripetal one radial (no moment), the
    // inertia -izz qdd: the spring turns by -(m L^2 + izz) qdd / k.
    let theta = -(m * 1.0 + izz) * qdd[0] / k;
    assert!((data.spring_moments[0].z - (-(m + izz) * qdd[0])).abs() < 1e-12);
    assert!((data.spring_angles[0].z - theta).abs() < 1e-15);
    assert!((d[5] - theta).abs() < 1e-15);
    // At rest and without gravity the masses load nothing: the paper's deflection.
    let rest = ArmMotion {
        qd: &[0.0],
        qdd: &[0.0],
        gravity: Vector3::zeros(),
    };
    let w = Vector6::new(0.0, 50.0, 0.0, 0.0, 0.0, 3.0);
    let a = vjm::deflection(&model, &mut data, &[0.2], &w, vjm::Load::ExactWithArm(rest)).unwrap();
    let b = vjm::deflection(&model, &mut data, &[0.2], &w, vjm::Load::Exact).unwrap();
    assert!((a - b).amax() < 1e-18, "{a} {b}");
}

#[test]
fn gravity_gives_the_weight_moment() {
    // A horizontal 1 m link along x, soft in bending about y at its root, 10 kg at the tip:
    // the weight's moment about y at the root is +m g L (z down: F = -m g z at x = L gives
    // M = L x (-m g z) = +m g L y).
    let model = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([INF, 2.0e4, INF])
        .unwrap()
        .mass(10.0, Vector3::new(1.0, 0.0, 0.0), Matrix3::zeros())
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    let g = Vector3::new(0.0, 0.0, -9.80665);
    let motion = ArmMotion {
        qd: &[0.0],
        qdd: &[0.0],
        gravity: g,
    };
    let d = vjm::deflection(
        &model,
        &mut data,
        &[0.0],
        &Vector6::zeros(),
        vjm::Load::ExactWithArm(motion),
    )
    .unwrap();
    let beta = 10.0 * 9.80665 / 2.0e4;
    assert!((data.spring_angles[0].y - beta).abs() < 1e-15);
    // The tip drops by sin(beta) (a rotation about +y turns +x towards -z).
    assert!((d[2] + beta.sin()).abs() < 1e-12, "{}", d[2]);
}

/// A 6-joint arm with springs on every joint and a mass on every link.
fn six_axis(tip_mass: Option<(f64, Vector3<f64>, Matrix3<f64>)>) -> vjm::Model {
    let mut b = fixtures::six_r(fixtures::Link::SpringAndMass([3.0e5, 2.0e5, 1.0e5]));
    if let Some((m, c, i)) = tip_mass {
        b = b.mass(m, c, i).unwrap();
    }
    b.build().unwrap()
}

const Q: [f64; 6] = [0.1, -0.4, 0.9, 0.2, 0.6, -0.3];
const QD: [f64; 6] = [0.5, -0.8, 1.1, 2.0, -1.5, 0.7];
const QDD: [f64; 6] = [3.0, 2.0, -4.0, 6.0, 5.0, -7.0];

#[test]
fn acceleration_bias_is_the_second_derivative_of_the_forward_kinematics() {
    let model = six_axis(None);
    let mut data = Data::new(&model);
    // q(t) = Q + QD t + QDD t^2 / 2: [a; alpha] = J QDD + bias.
    let bias = vjm::tcp_acceleration_bias(&model, &mut data, &Q, &QD).unwrap();
    vjm::joint_jacobian(&model, &mut data, &Q).unwrap();
    let j = data.jacobian.columns(0, 6).into_owned();
    let want_acc = j * nalgebra::Vector6::from_column_slice(&QDD) + bias;
    let h = 1e-4;
    let pose = |t: f64| {
        let q: Vec<f64> = (0..6)
            .map(|i| Q[i] + QD[i] * t + 0.5 * QDD[i] * t * t)
            .collect();
        vjm::forward(&model, &mut Data::new(&model), &q).unwrap()
    };
    let (pm, p0, pp) = (pose(-h), pose(0.0), pose(h));
    let a_fd =
        (pp.translation.vector - 2.0 * p0.translation.vector + pm.translation.vector) / (h * h);
    for k in 0..3 {
        assert!(
            (want_acc[k] - a_fd[k]).abs() < 1e-5 * a_fd.norm(),
            "{k}: {} {}",
            want_acc[k],
            a_fd[k]
        );
    }
    // Angular: w(t) = rotation vector rate; alpha = (w(h) - w(-h)) / 2h with w from poses.
    let w_at = |t: f64| {
        let (a, b) = (pose(t - h), pose(t + h));
        (b.rotation * a.rotation.inverse()).scaled_axis() / (2.0 * h)
    };
    let al_fd = (w_at(h) - w_at(-h)) / (2.0 * h);
    for k in 0..3 {
        assert!(
            (want_acc[3 + k] - al_fd[k]).abs() < 1e-4 * al_fd.norm(),
            "{k}"
        );
    }
}

#[test]
fn a_mass_at_the_tcp_loads_like_the_payload_formula() {
    // The same body as a link mass at the TCP or as the corrector's payload: identical
    // deflection (the payload formula of dalembert::serial against the recursive loads).
    let com = Vector3::new(0.02, -0.01, 0.15);
    let inertia = Matrix3::new(0.3, 0.01, 0.0, 0.01, 0.4, 0.02, 0.0, 0.02, 0.2);
    let payload = Payload {
        mass: 40.0,
        com,
        inertia,
    };
    let bare = six_axis(None);
    let with = six_axis(Some((40.0, com, inertia)));
    let motion = ArmMotion {
        qd: &QD,
        qdd: &QDD,
        gravity: Vector3::new(0.0, 0.0, -9.80665),
    };
    let mut data = Data::new(&bare);
    // The TCP's motion state from the joints.
    vjm::joint_jacobian(&bare, &mut data, &Q).unwrap();
    let j = data.jacobian.columns(0, 6).into_owned();
    let vel = &j * nalgebra::Vector6::from_column_slice(&QD);
    let acc = j * nalgebra::Vector6::from_column_slice(&QDD)
        + vjm::tcp_acceleration_bias(&bare, &mut data, &Q, &QD).unwrap();
    let tcp = vjm::forward(&bare, &mut data, &Q).unwrap();
    let state = PoseState {
        t: 0.0,
        pose: tcp,
        velocity: vel.fixed_rows::<3>(0).into_owned(),
        acceleration: acc.fixed_rows::<3>(0).into_owned(),
        angular_velocity: vel.fixed_rows::<3>(3).into_owned(),
        angular_acceleration: acc.fixed_rows::<3>(3).into_owned(),
    };
    let w = payload.loading_wrench(&state, &motion.gravity);
    let a = vjm::deflection(&bare, &mut data, &Q, &w, vjm::Load::ExactWithArm(motion)).unwrap();
    let mut data2 = Data::new(&with);
    let b = vjm::deflection(
        &with,
        &mut data2,
        &Q,
        &Vector6::zeros(),
        vjm::Load::ExactWithArm(motion),
    )
    .unwrap();
    assert!((a - b).amax() < 1e-12 * a.amax(), "{a} {b}");
    assert!(a.amax() > 1e-4, "a real deflection: {a}");
}

#[test]
fn linearized_is_first_order_and_errors_are_statuses() {
    let model = six_axis(None);
    let mut data = Data::new(&model);
    let gap = |s: f64, data: &mut Data| {
        let qdd: Vec<f64> = QDD.iter().map(|v| v * s).collect();
        let motion = ArmMotion {
            qd: &[0.0; 6],
            qdd: &qdd,
            gravity: Vector3::zeros(),
        };
        let e = vjm::deflection(
            &model,
            data,
            &Q,
            &Vector6::zeros(),
            vjm::Load::ExactWithArm(motion),
        )
        .unwrap();
        let l = vjm::deflection(
            &model,
            data,
            &Q,
            &Vector6::zeros(),
            vjm::Load::LinearizedWithArm(motion),
        )
        .unwrap();
        ((e - l).norm(), e.norm())
    };
    let (g1, d1) = gap(0.25, &mut data);
    let (g2, _) = gap(0.5, &mut data);
    assert!(g1 < 1e-2 * d1 && g1 > 0.0);
    assert!((g2 / g1 - 4.0).abs() < 0.1, "{}", g2 / g1);
    let ok = ArmMotion {
        qd: &QD,
        qdd: &QDD,
        gravity: Vector3::zeros(),
    };
    let w = Vector6::zeros();
    assert!(matches!(
        vjm::deflection(
            &model,
            &mut data,
            &Q,
            &w,
            vjm::Load::ExactWithArm(ArmMotion { qd: &QD[..5], ..ok })
        ),
        Err(TickError::WrongLength { what: "qd", .. })
    ));
    let nan = [f64::NAN; 6];
    assert!(matches!(
        vjm::deflection(
            &model,
            &mut data,
            &Q,
            &w,
            vjm::Load::ExactWithArm(ArmMotion { qdd: &nan, ..ok })
        ),
        Err(TickError::NonFinite { what: "qdd", .. })
    ));
    let huge = [1e200; 6];
    assert!(
        vjm::deflection(
            &model,
            &mut data,
            &Q,
            &w,
            vjm::Load::ExactWithArm(ArmMotion { qdd: &huge, ..ok })
        )
        .is_err()
    );
    // Builder checks.
    let b = || ModelBuilder::new().revolute(Vector3::z()).unwrap();
    assert!(b().mass(-1.0, Vector3::zeros(), Matrix3::zeros()).is_err());
    assert!(
        b().mass(1.0, Vector3::new(f64::NAN, 0.0, 0.0), Matrix3::zeros())
            .is_err()
    );
    assert!(
        b().mass(
            1.0,
            Vector3::zeros(),
            Matrix3::new(1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
        )
        .is_err()
    );
    assert!(
        b().mass(
            1.0,
            Vector3::zeros(),
            Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0))
        )
        .is_err()
    );
}
