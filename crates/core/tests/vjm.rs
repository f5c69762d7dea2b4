//! Hand-derived cases of the virtual-joint model (VJM paper, Eq. 1-9).

use approx::assert_relative_eq;
use deflect_core::vjm::{self, Data, Element, Vector6};
use deflect_core::{BuildError, ModelBuilder, TickError};
use nalgebra::{Isometry3, Matrix3, Rotation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

const INF: f64 = f64::INFINITY;

fn w(f: [f64; 6]) -> Vector6 {
    Vector6::from_row_slice(&f)
}

/// One spring at the base, soft about z, a rigid 1.2 m bar along x to the TCP.
#[test]
fn one_spring_bending_is_exact_rotation() {
    let (l, kz, fy) = (1.2, 2.0e4, 500.0);
    let model = ModelBuilder::new()
        .spring([INF, INF, kz])
        .unwrap()
        .fixed(Isometry3::translation(l, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    let d = vjm::deflection(
        &model,
        &mut data,
        &[],
        &w([0.0, fy, 0.0, 0.0, 0.0, 0.0]),
        vjm::Load::Exact,
    )
    .unwrap();
    // Eq. 6: M_A = r x F = L * Fy about z; Eq. 7: gamma = M_A / k_A = 0.03 rad.
    let gamma = l * fy / kz;
    assert_relative_eq!(gamma, 0.03, epsilon = 1e-15);
    // The bar turns rigidly by gamma about the base z axis.
    assert_relative_eq!(d[0], l * gamma.cos() - l, epsilon = 1e-15);
    assert_relative_eq!(d[1], l * gamma.sin(), epsilon = 1e-15);
    assert_relative_eq!(d[2], 0.0, epsilon = 1e-15);
    assert_relative_eq!(d[5], gamma, epsilon = 1e-15);
    assert_relative_eq!(data.spring_angles[0].z, gamma, epsilon = 1e-15);
    // The force along the bar loads nothing.
    let d = vjm::deflection(
        &model,
        &mut data,
        &[],
        &w([1e4, 0.0, 0.0, 0.0, 0.0, 0.0]),
        vjm::Load::Exact,
    )
    .unwrap();
    assert_eq!(d, Vector6::zeros());
}

/// Two springs in series, torques taken in the undeformed pose (Eq. 5-6).
#[test]
fn two_springs_in_series() {
    let (l1, l2, k1, k2, fy) = (0.8, 0.5, 5.0e4, 1.0e4, 300.0);
    let model = ModelBuilder::new()
        .spring([INF, INF, k1])
        .unwrap()
        .fixed(Isometry3::translation(l1, 0.0, 0.0))
        .unwrap()
        .spring([INF, INF, k2])
        .unwrap()
        .fixed(Isometry3::translation(l2, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    let d = vjm::deflection(
        &model,
        &mut data,
        &[],
        &w([0.0, fy, 0.0, 0.0, 0.0, 0.0]),
        vjm::Load::Exact,
    )
    .unwrap();
    let g1 = (l1 + l2) * fy / k1; // 7.8e-3 rad
    let g2 = l2 * fy / k2; // 15e-3 rad
    let x = l1 * g1.cos() + l2 * (g1 + g2).cos();
    let y = l1 * g1.sin() + l2 * (g1 + g2).sin();
    assert_relative_eq!(d[0], x - (l1 + l2), epsilon = 1e-15);
    assert_relative_eq!(d[1], y, epsilon = 1e-15);
    assert_relative_eq!(d[5], g1 + g2, epsilon = 1e-15);
    // y = 0.8 sin(0.0078) + 0.5 sin(0.0228) = 6.2399e-3 + 11.3990e-3 m
    assert_relative_eq!(d[1], 0.017_638_9, epsilon = 1e-7);
}

/// A pure moment reaches every spring unchanged; the three angles compose as
/// z-y'-x'' (Eq. 4), written out here element by element.
#[test]
fn moment_load_and_eq4_rotation() {
    let k = [2.0e3, 4.0e3, 8.0e3];
    let m = [30.0, -50.0, 70.0];
    let model = ModelBuilder::new()
        .spring(k)
        .unwrap()
        .fixed(Isometry3::translation(0.0, 0.0, 0.3))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    // Moment about the TCP: the spring sits 0.3 m below it, but a pure moment is free.
    let d = vjm::deflection(
        &model,
        &mut data,
        &[],
        &w([0.0, 0.0, 0.0, m[0], m[1], m[2]]),
        vjm::Load::Exact,
    )
    .unwrap();
    let (a, b, g) = (m[0] / k[0], m[1] / k[1], m[2] / k[2]);
    let (ca, sa, cb, sb, cg, sg) = (a.cos(), a.sin(), b.cos(), b.sin(), g.cos(), g.sin());
    #[rustfmt::skip]
    let r_star = Matrix3::new(
        cb * cg, sa * sb * cg - ca * sg, ca * sb * cg + sa * sg,
        cb * sg, sa * sb * sg + ca * cg, ca * sb * sg - sa * cg,
        -sb,     sa * cb,                ca * cb,
    );
    let rv = Rotation3::from_matrix_unchecked(r_star).scaled_axis();
    for i in 0..3 {
        assert_relative_eq!(d[3 + i], rv[i], epsilon = 1e-14);
    }
    // The TCP 0.3 m up the z axis swings with R*: dp = R* (0,0,0.3) - (0,0,0.3).
    let dp = r_star * Vector3::new(0.0, 0.0, 0.3) - Vector3::new(0.0, 0.0, 0.3);
    for i in 0..3 {
        assert_relative_eq!(d[i], dp[i], epsilon = 1e-15);
    }
}

/// A planar 2R arm with torsion springs: the linearized compliance is
/// `sum c_i J_i J_i^T` written out by hand.
fn planar_2r() -> deflect_core::Model {
    ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([INF, INF, 1.0e4])
        .unwrap()
        .fixed(Isometry3::translation(0.7, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .spring([INF, INF, 2.5e3])
        .unwrap()
        .fixed(Isometry3::translation(0.4, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap()
}

#[test]
fn planar_2r_compliance_by_hand() {
    let model = planar_2r();
    let mut data = Data::new(&model);
    let q = [0.4, -1.1];
    let c = vjm::compliance(&model, &mut data, &q).unwrap();
    // Spring 1 at the origin, spring 2 at the elbow; TCP at p.
    let elbow = Vector3::new(0.7 * 0.4f64.cos(), 0.7 * 0.4f64.sin(), 0.0);
    let p = elbow + Vector3::new(0.4 * (-0.7f64).cos(), 0.4 * (-0.7f64).sin(), 0.0);
    let mut expect = nalgebra::Matrix6::<f64>::zeros();
    for (origin, k) in [(Vector3::zeros(), 1.0e4), (elbow, 2.5e3)] {
        let r: Vector3<f64> = p - origin;
        // z x r = (-ry, rx, 0); angular part (0, 0, 1).
        let j: Vector6 = Vector6::new(-r.y, r.x, 0.0, 0.0, 0.0, 1.0);
        expect += j * j.transpose() / k;
    }
    assert_relative_eq!(c, expect, epsilon = 1e-18);
    // Same model through the joint Jacobian: spring axes coincide with the joints, so
    // C = J diag(1/k) J^T.
    vjm::joint_jacobian(&model, &mut data, &q).unwrap();
    let j = data.jacobian.fixed_columns::<2>(0).into_owned();
    let kinv = nalgebra::Matrix2::new(1.0e-4, 0.0, 0.0, 4.0e-4);
    assert_relative_eq!(c, j * kinv * j.transpose(), epsilon = 1e-18);
}

/// Exact and linearized agree to second order as the load goes to zero.
#[test]
fn exact_minus_linear_is_second_order() {
    let model = planar_2r();
    let mut data = Data::new(&model);
    let q = [0.4, -1.1];
    let c = vjm::compliance(&model, &mut data, &q).unwrap();
    let w0 = w([120.0, -80.0, 0.0, 0.0, 0.0, 15.0]);
    let err = |s: f64| {
        let d = vjm::deflection(
            &model,
            &mut Data::new(&model),
            &q,
            &(w0 * s),
            vjm::Load::Exact,
        )
        .unwrap();
        (d - c * (w0 * s)).norm()
    };
    let (e1, e2) = (err(1.0), err(0.1));
    assert!(
        e1 > 1e-9,
        "the exact model is non-linear at this load: {e1}"
    );
    // Halving the load by 10 divides a second-order error by 100 (within 2 %).
    assert_relative_eq!(e1 / e2, 100.0, max_relative = 0.02);
}

#[test]
fn zero_load_gives_zero_deflection() {
    let model = planar_2r();
    let d = vjm::deflection(
        &model,
        &mut Data::new(&model),
        &[0.3, 0.2],
        &Vector6::zeros(),
        vjm::Load::Exact,
    )
    .unwrap();
    assert_eq!(d, Vector6::zeros());
}

/// A prismatic joint carries the frame; springs after it see the shifted lever arm.
#[test]
fn prismatic_joint_moves_the_lever() {
    let model = ModelBuilder::new()
        .spring([INF, 1.0e4, INF])
        .unwrap()
        .prismatic(Vector3::x() * 3.0)
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    let t = vjm::forward(&model, &mut data, &[0.25]).unwrap();
    assert_relative_eq!(t.translation.vector, Vector3::new(0.25, 0.0, 0.0));
    let c = vjm::compliance(&model, &mut data, &[0.25]).unwrap();
    // Fz at 0.25 m: moment -0.25 Fz about y, dz = 0.25^2 / k per N.
    assert_relative_eq!(c[(2, 2)], 0.0625 / 1.0e4, epsilon = 1e-20);
}

#[test]
fn joint_correction_lands_the_deflected_tcp_on_target() {
    // Torsion springs coaxial with the joints: the deflected arm is the rigid arm with angles
    // q + dq + gamma, so dq = -gamma(q + dq) cancels position and orientation exactly.
    let model = planar_2r();
    let mut data = Data::new(&model);
    let q = [0.4, -1.1];
    let target = vjm::forward(&model, &mut data, &q).unwrap();
    let wr = w([200.0, -150.0, 0.0, 0.0, 0.0, 0.0]);
    let corr = vjm::joint_correction(&model, &mut data, &q, &wr, 30, 1e-14).unwrap();
    assert!(corr.converged, "{corr:?}");
    let qc = [q[0] + corr.dq[0], q[1] + corr.dq[1]];
    vjm::deflection(&model, &mut data, &qc, &wr, vjm::Load::Exact).unwrap();
    let gamma = [data.spring_angles[0].z, data.spring_angles[1].z];
    assert_relative_eq!(corr.dq[0], -gamma[0], epsilon = 1e-13);
    assert_relative_eq!(corr.dq[1], -gamma[1], epsilon = 1e-13);
    assert!((data.tcp_deflected.translation.vector - target.translation.vector).norm() < 1e-14);
    assert_eq!(corr.dq[2..], [0.0; 6]);
    // One step is the paper's first-order -J^+ delta: already within 5 % of the deflection.
    let d0 = vjm::deflection(&model, &mut data, &q, &wr, vjm::Load::Exact).unwrap();
    let one = vjm::joint_correction(&model, &mut data, &q, &wr, 1, 0.0).unwrap();
    assert!(!one.converged && one.iterations == 1);
    assert!(one.residual < 0.05 * d0.norm(), "{one:?}");
}

#[test]
fn under_actuated_correction_is_least_squares() {
    // The same arm but soft out of plane: a vertical load bends it out of the plane, which
    // no z joint can undo. The correction keeps the in-plane fixed point and flags it.
    let model = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([2.0e4, 2.0e4, 1.0e4])
        .unwrap()
        .fixed(Isometry3::translation(0.7, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .spring([2.0e4, 2.0e4, 2.5e3])
        .unwrap()
        .fixed(Isometry3::translation(0.4, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    let q = [0.4, -1.1];
    let target = vjm::forward(&model, &mut data, &q).unwrap();
    let wr = w([200.0, -150.0, -400.0, 0.0, 0.0, 0.0]);
    let before = vjm::deflection(&model, &mut data, &q, &wr, vjm::Load::Exact).unwrap();
    let corr = vjm::joint_correction(&model, &mut data, &q, &wr, 20, 1e-12).unwrap();
    // The least-squares fixed point is reached in a few steps; the iteration then stops on
    // its own (it used to spin through all 20 steps) and says why.
    assert!(
        !corr.converged && corr.stalled && corr.iterations < 20,
        "{corr:?}"
    );
    let qc = [q[0] + corr.dq[0], q[1] + corr.dq[1]];
    vjm::deflection(&model, &mut data, &qc, &wr, vjm::Load::Exact).unwrap();
    let e = data.tcp_deflected.translation.vector - target.translation.vector;
    // The out-of-plane sag stays; the in-plane error is far smaller than before.
    assert_relative_eq!(e.z, before[2], max_relative = 0.05);
    let inplane_before = (before[0].powi(2) + before[1].powi(2)).sqrt();
    assert!(inplane_before > 1e-2);
    assert!(
        (e.x.powi(2) + e.y.powi(2)).sqrt() < 0.1 * inplane_before,
        "{e:?}"
    );
}

#[test]
fn joint_correction_six_dof_converges_exactly() {
    // A spatial 6R arm with springs about every axis: 6 joints can cancel the full pose error.
    let mut b = ModelBuilder::new();
    let axes = [
        Vector3::z(),
        Vector3::y(),
        Vector3::y(),
        Vector3::x(),
        Vector3::y(),
        Vector3::x(),
    ];
    let offsets = [
        Vector3::new(0.0, 0.0, 0.4),
        Vector3::new(0.6, 0.0, 0.0),
        Vector3::new(0.5, 0.0, 0.05),
        Vector3::new(0.2, 0.0, 0.0),
        Vector3::new(0.1, 0.0, 0.0),
        Vector3::new(0.15, 0.0, 0.0),
    ];
    for (a, o) in axes.iter().zip(offsets) {
        b = b
            .revolute(*a)
            .unwrap()
            .spring([2.0e5, 2.0e5, 1.0e5])
            .unwrap()
            .fixed(Isometry3::translation(o.x, o.y, o.z))
            .unwrap();
    }
    let model = b.build().unwrap();
    let mut data = Data::new(&model);
    let q = [0.1, -0.4, 0.9, 0.2, 0.6, -0.3];
    let target = vjm::forward(&model, &mut data, &q).unwrap();
    let wr = w([300.0, -200.0, -500.0, 10.0, 0.0, -5.0]);
    let corr = vjm::joint_correction(&model, &mut data, &q, &wr, 10, 1e-13).unwrap();
    assert!(corr.converged && corr.iterations >= 2, "{corr:?}");
    let mut qc = q;
    for (qi, dq) in qc.iter_mut().zip(corr.dq) {
        *qi += dq;
    }
    vjm::deflection(&model, &mut data, &qc, &wr, vjm::Load::Exact).unwrap();
    let t = data.tcp_deflected;
    assert!((t.translation.vector - target.translation.vector).norm() < 1e-13);
    assert!((t.rotation * target.rotation.inverse()).angle() < 1e-13);
    // The commanded Cartesian pose moves the TCP against the deflection.
    let d = vjm::deflection(&model, &mut data, &q, &wr, vjm::Load::Exact).unwrap();
    let cmd = vjm::commanded_pose(&target, &d);
    let dp = cmd.translation.vector - target.translation.vector;
    assert_relative_eq!(dp, -d.fixed_rows::<3>(0).into_owned(), epsilon = 1e-15);
    let back = UnitQuaternion::from_scaled_axis(d.fixed_rows::<3>(3).into_owned()) * cmd.rotation;
    assert!((back.inverse() * target.rotation).angle() < 1e-14);
}

#[test]
fn singular_pose_is_reported() {
    // Two prismatic joints along the same axis: rank 1 where 2 is needed.
    let twin = ModelBuilder::new()
        .prismatic(Vector3::x())
        .unwrap()
        .prismatic(Vector3::x())
        .unwrap()
        .spring([1.0e3, 1.0e3, 1.0e3])
        .unwrap()
        .fixed(Isometry3::translation(0.0, 0.0, 0.5))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&twin);
    let r = vjm::joint_correction(
        &twin,
        &mut data,
        &[0.0, 0.0],
        &w([10.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        3,
        1e-12,
    );
    assert!(matches!(r, Err(TickError::Singular { sigma_min, .. }) if sigma_min < 1e-12));
}

#[test]
fn bad_inputs_are_typed_errors() {
    let model = planar_2r();
    let mut data = Data::new(&model);
    assert_eq!(
        vjm::forward(&model, &mut data, &[0.0]),
        Err(TickError::WrongLength {
            what: "q",
            expected: 2,
            got: 1
        })
    );
    assert_eq!(
        vjm::deflection(
            &model,
            &mut data,
            &[0.0, f64::NAN],
            &Vector6::zeros(),
            vjm::Load::Exact
        ),
        Err(TickError::NonFinite {
            what: "q",
            index: 1
        })
    );
    assert_eq!(
        vjm::deflection(
            &model,
            &mut data,
            &[0.0, 0.0],
            &w([0.0, 0.0, f64::INFINITY, 0.0, 0.0, 0.0]),
            vjm::Load::Exact
        ),
        Err(TickError::NonFinite {
            what: "wrench",
            index: 2
        })
    );
    assert_eq!(
        vjm::compliance(&model, &mut data, &[0.0, 0.0, 0.0]).unwrap_err(),
        TickError::WrongLength {
            what: "q",
            expected: 2,
            got: 3
        }
    );
}

#[test]
fn data_of_another_model_is_refused() {
    // A `Data` records the dof and springs of the model it was made for; every per-tick
    // function refuses it for a model of other dimensions.
    let two = planar_2r();
    let one = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([INF, INF, 1.0e4])
        .unwrap()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    assert_eq!((two.dof(), one.dof()), (2, 1));
    let mut data = Data::new(&two);
    assert!(data.check(&two));
    assert!(!data.check(&one));
    assert!(Data::new(&one).check(&one));
    assert!(!Data::new(&one).check(&two));
    let mismatch = TickError::ModelMismatch {
        what: "dof",
        expected: 1,
        got: 2,
    };
    let wr = w([0.0, 100.0, 0.0, 0.0, 0.0, 0.0]);
    // With q sized for either model: the model check comes first.
    for q in [&[0.3][..], &[0.3, -0.2][..]] {
        assert_eq!(vjm::forward(&one, &mut data, q).unwrap_err(), mismatch);
        assert_eq!(
            vjm::deflection(&one, &mut data, q, &wr, vjm::Load::Exact).unwrap_err(),
            mismatch
        );
        assert_eq!(vjm::compliance(&one, &mut data, q).unwrap_err(), mismatch);
        assert_eq!(
            vjm::joint_jacobian(&one, &mut data, q).unwrap_err(),
            mismatch
        );
        assert_eq!(
            vjm::joint_correction(&one, &mut data, q, &wr, 5, 1e-12).unwrap_err(),
            mismatch
        );
        assert_eq!(
            vjm::joint_delta(&one, &mut data, q, &wr).unwrap_err(),
            mismatch
        );
    }
    // The other way round, and the refused data still serves its own model.
    assert_eq!(
        vjm::forward(&two, &mut Data::new(&one), &[0.3, -0.2]).unwrap_err(),
        TickError::ModelMismatch {
            what: "dof",
            expected: 2,
            got: 1
        }
    );
    assert!(data.check(&two));
    vjm::deflection(&two, &mut data, &[0.3, -0.2], &wr, vjm::Load::Exact).unwrap();
    assert!(vjm::deflection(&one, &mut Data::new(&one), &[0.3], &wr, vjm::Load::Exact).is_ok());
}

#[test]
fn builder_rejects_bad_elements() {
    assert_eq!(
        ModelBuilder::new().revolute(Vector3::zeros()).unwrap_err(),
        BuildError::ZeroAxis { element: 0 }
    );
    assert_eq!(
        ModelBuilder::new()
            .fixed(Isometry3::translation(f64::NAN, 0.0, 0.0))
            .unwrap_err(),
        BuildError::NonFinite {
            what: "transform",
            index: 0
        }
    );
    let e = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .spring([1.0, -2.0, 3.0])
        .unwrap_err();
    assert_eq!(
        e,
        BuildError::NonPositiveStiffness {
            element: 1,
            axis: 1,
            value: -2.0
        }
    );
    assert!(e.to_string().contains("about axis y is -2"));
    assert!(matches!(
        ModelBuilder::new().spring([1.0, f64::NAN, 1.0]),
        Err(BuildError::NonPositiveStiffness { axis: 1, .. })
    ));
    let mut b = ModelBuilder::new();
    for _ in 0..deflect_core::vjm::MAX_DOF {
        b = b.revolute(Vector3::z()).unwrap();
    }
    assert_eq!(
        b.revolute(Vector3::z()).unwrap_err(),
        BuildError::Capacity {
            what: "joints",
            capacity: deflect_core::vjm::MAX_DOF,
            got: deflect_core::vjm::MAX_DOF + 1
        }
    );
}

#[test]
fn spring_inside_a_link_is_undone_after_the_spring() {
    let frame = Isometry3::new(Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.3, -0.2, 0.5));
    let model = ModelBuilder::new()
        .fixed(Isometry3::translation(1.0, 0.0, 0.0))
        .unwrap()
        .spring_at(frame, [1.0e4, 1.0e4, 1.0e4])
        .unwrap()
        .build()
        .unwrap();
    // Rigid FK is unchanged by the spring placement.
    let t = vjm::forward(&model, &mut Data::new(&model), &[]).unwrap();
    assert_relative_eq!(
        t.translation.vector,
        Vector3::new(1.0, 0.0, 0.0),
        epsilon = 1e-15
    );
    assert!(
        model
            .elements()
            .iter()
            .any(|e| matches!(e, Element::Spring { index: 0, .. }))
    );
}

proptest! {
    /// For small loads the exact model matches `C w` to second order in every pose.
    #[test]
    fn small_loads_are_linear(q0 in -3.0..3.0f64, q1 in -3.0..3.0f64,
                              fx in -1.0..1.0f64, fy in -1.0..1.0f64, mz in -1.0..1.0f64) {
        let model = planar_2r();
        let mut data = Data::new(&model);
        let c = vjm::compliance(&model, &mut data, &[q0, q1]).unwrap();
        let wr = w([fx, fy, 0.0, 0.0, 0.0, mz]);
        let d = vjm::deflection(&model, &mut data, &[q0, q1], &wr, vjm::Load::Exact).unwrap();
        let lin = c * wr;
        // |w| <= 1.7 N gives angles below 4e-4 rad: second-order terms below 1e-6 of |lin|.
        prop_assert!((d - lin).norm() <= 1e-3 * lin.norm() + 1e-15);
    }
}

#[test]
fn a_model_rebuilt_from_its_elements_computes_bit_for_bit_the_same() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/kr300/");
    let robot = deflect_core::SerialRobot::from_path(
        format!("{dir}kr300_r2500.urdf"),
        format!("{dir}kr300_r2500_stiffness.toml"),
        "tcp",
    )
    .unwrap();
    let model = &robot.model;
    let rebuilt = model
        .elements()
        .iter()
        .try_fold(ModelBuilder::new(), |b, e| b.element(*e))
        .and_then(|b| b.build())
        .unwrap();
    assert_eq!(rebuilt.elements(), model.elements());
    assert_eq!(rebuilt.mass_count(), 6);
    let q = [0.3, -0.8, 1.2, 0.5, 0.9, -0.4];
    let w = Vector6::new(-386.1, 386.1, -60.0, 12.0, -7.0, 3.0);
    let (mut a, mut b) = (Data::new(model), Data::new(&rebuilt));
    assert_eq!(
        vjm::deflection(model, &mut a, &q, &w, vjm::Load::Exact).unwrap(),
        vjm::deflection(&rebuilt, &mut b, &q, &w, vjm::Load::Exact).unwrap()
    );
    assert_eq!(
        vjm::compliance(model, &mut a, &q).unwrap(),
        vjm::compliance(&rebuilt, &mut b, &q).unwrap()
    );
    // A tampered element is refused, not normalized or clamped.
    let long_axis = Element::Revolute {
        axis: nalgebra::Unit::new_unchecked(Vector3::new(0.0, 0.0, 2.0)),
        index: 0,
    };
    assert!(matches!(
        ModelBuilder::new().element(long_axis),
        Err(BuildError::InvalidParameter { value, .. }) if value == 2.0
    ));
    let negative = Element::Spring {
        compliance: Vector3::new(1e-6, -1e-6, 0.0),
        index: 0,
        offset: Isometry3::identity(),
    };
    assert!(matches!(
        ModelBuilder::new().element(negative),
        Err(BuildError::NonPositiveStiffness { axis: 1, .. })
    ));
}

/// The kernels' compiled passes against the definitions: the rigid TCP of `forward` (joints
/// only, fixed transforms folded across springs) equals the one of the full pass, and the
/// compliance (3 x 3 blocks per spring) equals `sum J_s K_s^-1 J_s^T` built column by column
/// from the spring frames, on a chain with spring offsets, a prismatic joint, an oblique
/// axis and springs between fixed transforms.
#[test]
fn compiled_passes_equal_the_definitions() {
    let oblique = Vector3::new(0.3, -0.5, 0.81).normalize();
    let offset = Isometry3::from_parts(
        Vector3::new(0.01, -0.02, 0.03).into(),
        UnitQuaternion::from_euler_angles(0.2, -0.4, 0.9),
    );
    let model = ModelBuilder::new()
        .fixed(Isometry3::translation(0.0, 0.0, 0.4))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .spring([2.0e5, 3.0e5, 4.0e4])
        .unwrap()
        .fixed(Isometry3::from_parts(
            Vector3::new(0.1, 0.0, 0.2).into(),
            UnitQuaternion::from_euler_angles(-0.3, 0.1, 0.2),
        ))
        .unwrap()
        .element(Element::Spring {
            compliance: Vector3::new(1.0 / 5.0e4, 0.0, 1.0 / 7.0e4),
            index: 1,
            offset,
        })
        .unwrap()
        .fixed(Isometry3::translation(0.6, 0.05, 0.0))
        .unwrap()
        .revolute(oblique)
        .unwrap()
        .prismatic(Vector3::x())
        .unwrap()
        .spring([3.0e4, INF, 1.0e4])
        .unwrap()
        .fixed(Isometry3::translation(0.3, 0.0, -0.1))
        .unwrap()
        .build()
        .unwrap();
    let mut data = Data::new(&model);
    let q = [0.7, -1.2, 0.15];
    let wrench = w([120.0, -80.0, 45.0, 3.0, -2.0, 1.5]);
    let tcp = vjm::forward(&model, &mut data, &q).unwrap();
    vjm::deflection(&model, &mut data, &q, &wrench, vjm::Load::Exact).unwrap();
    assert_relative_eq!(
        tcp.translation.vector,
        data.tcp.translation.vector,
        epsilon = 1e-15
    );
    assert!(tcp.rotation.angle_to(&data.tcp.rotation) < 1e-15);
    // Walk the elements by hand: the spring frames and the TCP.
    let mut t = Isometry3::identity();
    let mut qi = q.iter();
    let mut springs = Vec::new();
    for e in model.elements() {
        match *e {
            Element::Fixed(m) => t *= m,
            Element::Revolute { axis, .. } => {
                t *= UnitQuaternion::from_axis_angle(&axis, *qi.next().unwrap())
            }
            Element::Prismatic { axis, .. } => {
                t *= nalgebra::Translation3::from(axis.into_inner() * *qi.next().unwrap())
            }
            Element::Spring {
                compliance, offset, ..
            } => springs.push((t * offset, compliance)),
            Element::Mass { .. } => {}
        }
    }
    assert_relative_eq!(
        t.translation.vector,
        tcp.translation.vector,
        epsilon = 1e-15
    );
    let mut expect = nalgebra::Matrix6::<f64>::zeros();
    for (f, c) in &springs {
        let r = t.translation.vector - f.translation.vector;
        for (a, ca) in c.iter().enumerate() {
            let u = f.rotation * Vector3::ith(a, 1.0);
            let lin = u.cross(&r);
            let col = Vector6::new(lin.x, lin.y, lin.z, u.x, u.y, u.z);
            expect += col * col.transpose() * *ca;
        }
    }
    let c = vjm::compliance(&model, &mut data, &q).unwrap();
    assert_relative_eq!(c, expect, max_relative = 1e-12, epsilon = 1e-22);
    assert_eq!(c, c.transpose(), "symmetric to the bit");
    // The linearized load is C w: the same sum taken spring by spring (each spring's turn
    // to first order) in the deflection's one pass, so equal to rounding.
    let d = vjm::deflection(&model, &mut data, &q, &wrench, vjm::Load::Linearized).unwrap();
    let cw = c * wrench;
    assert_relative_eq!(d, cw, max_relative = 1e-14, epsilon = 1e-15 * cw.amax());
    let mut bad = wrench;
    bad[4] = f64::NAN;
    assert_eq!(
        vjm::deflection(&model, &mut data, &q, &bad, vjm::Load::Linearized),
        Err(TickError::NonFinite {
            what: "wrench",
            index: 4
        })
    );
}
