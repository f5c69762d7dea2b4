//! Hand-derived cases of the virtual-joint model (VJM paper, Eq. 1-9): deflection, compliance
//! and the compiled passes against their definitions.

use approx::assert_relative_eq;
use deflect_core::vjm::{self, Data, Element, Vector6};
use deflect_core::{ModelBuilder, TickError};
use nalgebra::{Isometry3, Matrix3, Rotation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

mod fixtures;

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

#[test]
fn planar_2r_compliance_by_hand() {
    let model = fixtures::planar_2r();
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
    let model = fixtures::planar_2r();
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

proptest! {
    /// For small loads the exact model matches `C w` to second order in every pose.
    #[test]
    fn small_loads_are_linear(q0 in -3.0..3.0f64, q1 in -3.0..3.0f64,
                              fx in -1.0..1.0f64, fy in -1.0..1.0f64, mz in -1.0..1.0f64) {
        let model = fixtures::planar_2r();
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
fn zero_load_gives_zero_deflection() {
    let model = fixtures::planar_2r();
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

/// Three joints (a revolute one, an oblique one, a prismatic one) and three springs, one
/// with an offset from its element and two between fixed transforms with rotations.
fn offset_chain() -> vjm::Model {
    let oblique = Vector3::new(0.3, -0.5, 0.81).normalize();
    let offset = Isometry3::from_parts(
        Vector3::new(0.01, -0.02, 0.03).into(),
        UnitQuaternion::from_euler_angles(0.2, -0.4, 0.9),
    );
    ModelBuilder::new()
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
        .unwrap()
}

/// The kernels' compiled passes against the definitions: the rigid TCP of `forward` (joints
/// only, fixed transforms folded across springs) equals the one of the full pass, and the
/// compliance (3 x 3 blocks per spring) equals `sum J_s K_s^-1 J_s^T` built column by column
/// from the spring frames, on a chain with spring offsets, a prismatic joint, an oblique
/// axis and springs between fixed transforms.
#[test]
fn compiled_passes_equal_the_definitions() {
    let model = offset_chain();
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

/// `linear_deflection` is the linearized `deflection` without its by-products: the same
/// deflection and rigid TCP bit for bit and the same errors, on [`offset_chain`] (a prismatic
/// joint, whose lever the lighter pass still moves), and `data.jacobian`,
/// `data.tcp_deflected` and the springs' moments and angles left as the last call filled
/// them.
#[test]
fn linear_deflection_alone_is_the_linearized_pass() {
    let model = offset_chain();
    let (mut full, mut alone) = (Data::new(&model), Data::new(&model));
    let loads = [
        ([0.7, -1.2, 0.15], [120.0, -80.0, 45.0, 3.0, -2.0, 1.5]),
        ([-2.9, 0.4, -0.3], [-15.0, 60.0, 210.0, -7.0, 0.5, 4.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
    ];
    for (q, f) in loads {
        let wrench = w(f);
        let d = vjm::deflection(&model, &mut full, &q, &wrench, vjm::Load::Linearized).unwrap();
        let kept = |d: &Data| {
            (
                d.jacobian,
                d.tcp_deflected,
                d.spring_angles,
                d.spring_moments,
            )
        };
        let before = kept(&alone);
        assert_eq!(
            vjm::linear_deflection(&model, &mut alone, &q, &wrench),
            Ok(d)
        );
        assert_eq!(alone.tcp, full.tcp);
        assert_eq!(kept(&alone), before);
    }
    let q = [0.7, -1.2, 0.15];
    let wrench = w([120.0, -80.0, 45.0, 3.0, -2.0, 1.5]);
    let mut bad = wrench;
    bad[4] = f64::NAN;
    let far = wrench * 1.0e6; // turns a spring past MAX_SPRING_ANGLE
    let overflow = wrench * 1.0e306; // moments past f64::MAX: infinite and NaN angles
    let one_spring = ModelBuilder::new()
        .spring([1.0e4; 3])
        .unwrap()
        .build()
        .unwrap();
    let other = Data::new(&one_spring);
    for (q, wrench, data) in [
        (&q[..], bad, &full),
        (&q[..2], wrench, &full),
        (&[0.7, f64::INFINITY, 0.15][..], wrench, &full),
        (&q[..], far, &full),
        (&q[..], overflow, &full),
        (&q[..], wrench, &other),
    ] {
        let expect = vjm::deflection(&model, &mut data.clone(), q, &wrench, vjm::Load::Linearized);
        assert!(expect.is_err(), "{q:?} {wrench:?}");
        assert_eq!(
            vjm::linear_deflection(&model, &mut data.clone(), q, &wrench),
            expect
        );
    }
}

/// The four-row path of `deflection_batch` on [`offset_chain`] (a prismatic joint, an oblique
/// axis, a spring offset, springs between fixed transforms): each row the one-row deflection
/// exactly (`==`).
#[test]
fn four_rows_with_a_prismatic_joint_are_the_one_row_path() {
    let model = offset_chain();
    let mut data = Data::new(&model);
    let q = [
        [0.7, 0.2, -1.2],
        [-2.0, -0.4, 0.3],
        [0.0, 0.0, 0.0],
        [3.1, 1.5, -3.0],
    ];
    let wrenches = [
        w([120.0, -80.0, 45.0, 3.0, -2.0, 1.5]),
        w([0.0, 0.0, -500.0, 0.0, 0.0, 0.0]),
        w([10.0, 20.0, 30.0, 40.0, 50.0, 60.0]),
        w([-300.0, 100.0, 0.0, 0.0, 12.0, 0.0]),
    ];
    let rows = vjm::exact_deflection_x4(
        &model,
        &data,
        q.each_ref().map(|q| q.as_slice()),
        wrenches.each_ref(),
    )
    .unwrap();
    for ((q, wr), d) in q.iter().zip(&wrenches).zip(rows) {
        let one = vjm::deflection(&model, &mut data, q, wr, vjm::Load::Exact).unwrap();
        assert_eq!(d, one, "{q:?}");
    }
}
