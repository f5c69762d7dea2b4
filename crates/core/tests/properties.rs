//! Property tests of core invariants, bounded to a few seconds in total (64 cases each):
//! the linearized compliance is the exact deflection to second order, a map reproduces its
//! nodes, and the planner never exceeds its limits.

use deflect_core::compliance_map::{ComplianceMap, Interpolation, QueryOptions};
use deflect_core::motion::{Limits, Trajectory};
use deflect_core::vjm::{self, Data, Model, ModelBuilder, Vector6};
use nalgebra::{Isometry3, Vector2, Vector3};
use proptest::prelude::*;

mod fixtures;

/// A spatial 6R arm with a spring about every axis of every joint.
fn arm(k: &[f64; 6]) -> Model {
    let axes = fixtures::SIX_R_AXES;
    let offsets = [
        Vector3::new(0.0, 0.0, 0.4),
        Vector3::new(0.6, 0.0, 0.0),
        Vector3::new(0.5, 0.0, 0.1),
        Vector3::new(0.2, 0.0, 0.0),
        Vector3::new(0.1, 0.0, 0.0),
        Vector3::new(0.15, 0.0, 0.0),
    ];
    let mut b = ModelBuilder::new();
    for ((axis, off), &ki) in axes.iter().zip(&offsets).zip(k) {
        b = b
            .revolute(*axis)
            .unwrap()
            .spring([ki, 0.8 * ki, 1.3 * ki])
            .unwrap()
            .fixed(Isometry3::translation(off.x, off.y, off.z))
            .unwrap();
    }
    b.build().unwrap()
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 64,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    /// `deflection(w) = C w + O(|w|^2)`: halving the load quarters the linearization error.
    #[test]
    fn compliance_is_the_deflection_to_second_order(
        q in proptest::array::uniform6(-2.5f64..2.5),
        k in proptest::array::uniform6(2.0e5f64..5.0e6),
        w in proptest::array::uniform6(-1.0f64..1.0),
        scale in 50.0f64..500.0,
    ) {
        let model = arm(&k);
        let mut data = Data::new(&model);
        let w = Vector6::from_row_slice(&w) * scale;
        let c = vjm::compliance(&model, &mut data, &q).unwrap();
        let err = |w: &Vector6, data: &mut Data| {
            let d = vjm::deflection(&model, data, &q, w, vjm::Load::Exact).unwrap();
            (d - c * w).norm()
        };
        let (e1, e2) = (err(&w, &mut data), err(&(w * 0.5), &mut data));
        let lin = (c * w).norm();
        // Second order: the error is small against the deflection and scales with |w|^2.
        prop_assert!(e1 <= 1e-2 * lin + 1e-15, "e1 {e1} lin {lin}");
        if e1 > 1e-13 {
            let ratio = e1 / e2;
            prop_assert!((3.0..5.0).contains(&ratio), "ratio {ratio}");
        }
    }

    /// At a node, both interpolations return the node's own lines (Eq. 9-10) exactly.
    #[test]
    fn map_reproduces_its_nodes(
        dx in proptest::collection::vec(0.01f64..0.1, 3),
        dy in proptest::collection::vec(0.01f64..0.1, 4),
        coeffs in proptest::collection::vec(-1e-5f64..1e-5, 2 * 20 * 4),
        f in proptest::array::uniform2(-300.0f64..300.0),
        node in (0usize..4, 0usize..5),
        bicubic in proptest::bool::ANY,
    ) {
        let x: Vec<f64> = std::iter::once(0.1).chain(dx.iter().scan(0.1, |a, d| { *a += d; Some(*a) })).collect();
        let y: Vec<f64> = std::iter::once(-0.1).chain(dy.iter().scan(-0.1, |a, d| { *a += d; Some(*a) })).collect();
        let n = x.len() * y.len() * 4;
        let map = ComplianceMap::new(
            x.clone(), y.clone(), 2, 2,
            coeffs[..n].to_vec(), coeffs[n..2 * n].iter().map(|c| c * 1e-2).collect(),
        ).unwrap();
        let (i, j) = node;
        let mut want = [0.0; 2];
        map.node_displacement(i, j, &f, &mut want).unwrap();
        let mut got = [0.0; 2];
        let interpolation = if bicubic { Interpolation::Bicubic } else { Interpolation::Bilinear };
        map.displacement_with([x[i], y[j]], &f, &mut got, QueryOptions { interpolation, ..QueryOptions::default() }).unwrap();
        for (g, w) in got.iter().zip(&want) {
            prop_assert!((g - w).abs() <= 1e-15 + 1e-12 * w.abs(), "{got:?} vs {want:?}");
        }
    }

    /// Speed, acceleration and jerk stay within their limits along the whole motion, which
    /// ends exactly at its end point, and takes at least `L / v_max`.
    #[test]
    fn planner_never_exceeds_its_limits(
        v in 0.05f64..2.0, a in 0.5f64..50.0, j in 5.0f64..5000.0,
        p in proptest::collection::vec(proptest::array::uniform2(-0.5f64..0.5), 2..5),
    ) {
        let points: Vec<Vector2<f64>> = p.iter().map(|q| Vector2::new(q[0], q[1])).collect();
        let lim = Limits::new(v, a, j).unwrap();
        let traj = Trajectory::polyline(&points, &lim).unwrap();
        let tol = 1.0 + 1e-9;
        for s in traj.ticks(1000.0).unwrap() {
            prop_assert!(s.velocity.norm() <= v * tol, "v {}", s.velocity.norm());
            prop_assert!(s.acceleration.norm() <= a * tol, "a {}", s.acceleration.norm());
            prop_assert!(s.jerk.norm() <= j * tol, "j {}", s.jerk.norm());
        }
        let end = traj.sample(traj.duration()).unwrap();
        prop_assert_eq!(end.position, *points.last().unwrap());
        prop_assert!(traj.duration() * v >= traj.path_length() * (1.0 - 1e-12));
    }
}

/// The paper's deflection computed the direct way, as a reference for the kernel: walk the
/// chain with quaternion isometries, take each spring's moment in the rigid pose, insert
/// its z-y'-x'' rotation into a second, deflected walk.
fn reference_deflection(model: &Model, q: &[f64], w: &Vector6) -> Vector6 {
    use deflect_core::vjm::Element;
    use nalgebra::{Translation3, UnitQuaternion};
    let joint = |e: &Element| match *e {
        Element::Fixed(t) => Some(t),
        Element::Revolute { axis, index } => Some(Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&axis, q[index]),
        )),
        Element::Prismatic { axis, index } => Some(Isometry3::from_parts(
            Translation3::from(axis.into_inner() * q[index]),
            UnitQuaternion::identity(),
        )),
        // A link mass moves nothing: it loads the springs only under motion or gravity.
        Element::Spring { .. } | Element::Mass { .. } => None,
    };
    let tcp = model
        .elements()
        .iter()
        .filter_map(joint)
        .fold(Isometry3::identity(), |t, m| t * m);
    let (f, m) = (
        Vector3::new(w[0], w[1], w[2]),
        Vector3::new(w[3], w[4], w[5]),
    );
    let (mut rigid, mut deflected) = (Isometry3::identity(), Isometry3::identity());
    for e in model.elements() {
        match (joint(e), e) {
            (Some(t), _) => {
                rigid *= t;
                deflected *= t;
            }
            (
                None,
                Element::Spring {
                    compliance, offset, ..
                },
            ) => {
                let s = rigid * offset;
                let ml = s.rotation.inverse()
                    * (m + (tcp.translation.vector - s.translation.vector).cross(&f));
                let a = compliance.component_mul(&ml);
                let rstar = UnitQuaternion::from_euler_angles(a.x, a.y, a.z);
                deflected = deflected
                    * offset
                    * Isometry3::from_parts(Translation3::identity(), rstar)
                    * offset.inverse();
            }
            _ => {}
        }
    }
    let dp = deflected.translation.vector - tcp.translation.vector;
    let dr = (deflected.rotation * tcp.rotation.inverse()).scaled_axis();
    Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z)
}

proptest! {
    #![proptest_config(config())]

    /// The kernel (rotation matrices, one rigid pass, springs composed about their origins)
    /// equals the direct quaternion walk to 1e-12 relative, springs with offsets included.
    #[test]
    fn kernel_equals_the_direct_walk(
        q in proptest::array::uniform6(-2.5f64..2.5),
        k in proptest::array::uniform6(2.0e5f64..5.0e6),
        w in proptest::array::uniform6(-1.0f64..1.0),
        off in proptest::array::uniform6(-0.5f64..0.5),
    ) {
        let mut b = ModelBuilder::new()
            .spring_at(Isometry3::new(Vector3::new(off[0], off[1], off[2]), Vector3::new(off[3], off[4], off[5])), [k[0], k[1], k[2]])
            .unwrap();
        for (i, axis) in [Vector3::z(), Vector3::y(), Vector3::new(0.3, 1.0, -0.2)].iter().enumerate() {
            b = b
                .revolute(*axis).unwrap()
                .spring_at(Isometry3::new(Vector3::new(off[i], 0.1, 0.0), Vector3::new(0.0, off[i + 3], 0.0)), [k[i + 3], 2.0 * k[i], f64::INFINITY]).unwrap()
                .fixed(Isometry3::translation(0.4, 0.05 * i as f64, 0.1)).unwrap();
        }
        b = b.prismatic(Vector3::new(1.0, 0.0, 0.2)).unwrap().spring([k[5], k[4], k[3]]).unwrap();
        let model = b.build().unwrap();
        let mut data = Data::new(&model);
        let qs = [q[0], q[1], q[2], 0.1 * q[3]];
        let w = Vector6::from_row_slice(&w) * 300.0;
        let got = vjm::deflection(&model, &mut data, &qs, &w, vjm::Load::Exact).unwrap();
        let want = reference_deflection(&model, &qs, &w);
        let scale = want.norm();
        // Both subtract poses about a metre long, each composed over eight frames: rounding
        // leaves up to ~10 ulps of 1 m (2.2e-15 m) in each, seen at 2.4e-15 m apart.
        prop_assert!((got - want).norm() <= 1e-12 * scale + 1e-14, "{got:?} vs {want:?}");
    }
}
