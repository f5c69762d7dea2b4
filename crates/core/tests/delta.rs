//! The Delta robot of Clavel: IK and FK inverse to each other over the workspace, the Jacobian
//! equal to finite differences of FK, the constraint lengths by hand, singular and unreachable
//! points typed, and the paper's D'Alembert corrector on it with a 3-D compliance map.

use deflect_core::TickError;
use deflect_core::compliance_map::GridMap;
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::mechanism::{Delta, Mechanism};
use nalgebra::{Matrix3, Vector3};

/// A grid of platform positions over the useful workspace of the pick-and-place Delta: a
/// cylinder of radius 0.4 m from 0.55 to 1.0 m below the base.
fn workspace() -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    for iz in 0..10 {
        let z = -0.55 - 0.05 * f64::from(iz);
        for ir in 0..5 {
            let r = 0.1 * f64::from(ir);
            for ia in 0..12 {
                let a = f64::from(ia) * std::f64::consts::PI / 6.0 + 0.1;
                out.push(Vector3::new(r * a.cos(), r * a.sin(), z));
            }
        }
    }
    out
}

#[test]
fn ik_and_fk_are_inverse_over_the_workspace_and_close_every_loop() {
    let d = Delta::pick_and_place();
    let (mut worst_p, mut worst_q, mut n) = (0.0f64, 0.0f64, 0);
    for p in workspace() {
        let Ok(q) = d.ik(&p) else { continue };
        n += 1;
        let back = d.fk(&q).unwrap();
        worst_p = worst_p.max((back - p).norm());
        worst_q = worst_q.max((d.ik(&back).unwrap() - q).amax());
        // Each forearm has its length, by hand from the elbows (module docs' geometry).
        for (i, theta) in q.iter().enumerate() {
            let phi = 2.0 * std::f64::consts::PI * i as f64 / 3.0;
            let u = Vector3::new(phi.cos(), phi.sin(), 0.0);
            let elbow = u * (0.2 + 0.35 * theta.cos()) - Vector3::z() * 0.35 * theta.sin();
            let joint = p + u * 0.045;
            assert!(((joint - elbow).norm() - 0.8).abs() < 1e-12);
            // Elbows out: of the two arm angles that close this forearm (found by scanning
            // the arm's circle for the sign changes of |joint - elbow|^2 - l^2 and bisecting,
            // not by the IK's formula), the IK took the one with the larger radial reach.
            let g = |t: f64| {
                let e = u * (0.2 + 0.35 * t.cos()) - Vector3::z() * 0.35 * t.sin();
                (joint - e).norm_squared() - 0.64
            };
            let mut roots = Vec::new();
            let steps = 720;
            for k in 0..steps {
                let tau = 2.0 * std::f64::consts::PI;
                let (mut a, mut b) = (
                    -std::f64::consts::PI + tau * k as f64 / steps as f64,
                    -std::f64::consts::PI + tau * (k + 1) as f64 / steps as f64,
                );
                if g(a).signum() == g(b).signum() {
                    continue;
                }
                for _ in 0..60 {
                    let m = 0.5 * (a + b);
                    if g(a).signum() == g(m).signum() {
                        a = m
                    } else {
                        b = m
                    }
                }
                roots.push(0.5 * (a + b));
            }
            assert_eq!(roots.len(), 2, "{p:?} arm {i}: {roots:?}");
            let out = roots.iter().copied().fold(f64::NAN, |best, t| {
                if best.is_nan() || t.cos() > best.cos() {
                    t
                } else {
                    best
                }
            });
            assert!(
                (theta - out).abs() < 1e-9,
                "{p:?} arm {i}: ik {theta}, elbow-out root {out}"
            );
        }
    }
    assert!(n > 500, "{n} of 600 workspace points reachable");
    assert!(worst_p < 1e-12, "FK(IK(p)) - p: {worst_p:e} m");
    assert!(worst_q < 1e-12, "IK(FK(q)) - q: {worst_q:e} rad");
}

#[test]
fn the_jacobian_is_the_derivative_of_fk() {
    let d = Delta::pick_and_place();
    let mut data = ();
    let h = 1e-6;
    let mut worst = 0.0f64;
    for p in workspace().into_iter().step_by(7) {
        let Ok(q) = d.ik(&p) else { continue };
        let j = <Delta as Mechanism<3, 3>>::jacobian(&d, &mut data, &q).unwrap();
        let mut fd = Matrix3::zeros();
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = h;
            let col = (d.fk(&(q + e)).unwrap() - d.fk(&(q - e)).unwrap()) / (2.0 * h);
            fd.set_column(k, &col);
        }
        worst = worst.max((j - fd).amax());
    }
    assert!(worst < 1e-7, "{worst:e} m/rad");
}

#[test]
fn unreachable_and_singular_points_are_typed() {
    let d = Delta::pick_and_place();
    // Far below the reach of arm plus forearm.
    assert!(matches!(
        d.ik(&Vector3::new(0.0, 0.0, -1.5)),
        Err(TickError::OutOfWorkspace { .. })
    ));
    assert!(matches!(
        d.ik(&Vector3::new(f64::NAN, 0.0, -0.7)),
        Err(TickError::NonFinite { .. })
    ));
    // Joints that cannot be assembled: with 0.3 m forearms and the arms horizontal, the
    // spheres' centres lie 0.505 m from the axis, farther than a forearm: they do not meet.
    let short = Delta::new(0.2, 0.045, 0.35, 0.3).unwrap();
    assert!(matches!(
        short.fk(&Vector3::zeros()),
        Err(TickError::OutOfWorkspace { .. })
    ));
    // Forearms stretched in line with the arms: the serial singularity of the arm, reached
    // at the edge of the workspace; its Jacobian is refused below the threshold.
    let mut data = ();
    let (mut inside, mut outside) = (0.3, 1.5);
    for _ in 0..60 {
        let mid = 0.5 * (inside + outside);
        if d.ik(&Vector3::new(mid, 0.0, -0.6)).is_ok() {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    let edge = Vector3::new(inside, 0.0, -0.6);
    let q = d.ik(&edge).unwrap();
    assert!(matches!(
        <Delta as Mechanism<3, 3>>::inverse(&d, &mut data, &edge, &q),
        Err(TickError::Singular { .. })
    ));
    let sigma = <Delta as Mechanism<3, 3>>::singularity_distance(&d, &mut data, &q).unwrap();
    assert!(sigma < d.min_sigma(), "{sigma}");
    // Bad dimensions are build errors.
    assert!(Delta::new(0.2, 0.045, 0.35, 0.1).is_err());
    assert!(Delta::new(-0.2, 0.045, 0.35, 0.8).is_err());
}

#[test]
fn the_dalembert_corrector_drives_a_delta_with_a_3d_map() {
    // A uniform map: 2 um/N along z, 1 um/N in x and y, no offsets, over the workspace.
    let axes = vec![vec![-0.4, 0.4], vec![-0.4, 0.4], vec![-1.0, -0.5]];
    let block = [1e-6, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, 2e-6];
    let slopes = block.repeat(8);
    let names = ["x", "y", "z"].map(String::from).to_vec();
    let map = GridMap::new(axes, names, 3, 3, slopes, vec![0.0; 72]).unwrap();
    let d = Delta::pick_and_place();
    let model = Model::new(d, map, 1.5).unwrap();
    let mut data = Data::new(&model);
    let p = Vector3::new(0.1, -0.05, -0.8);
    // 8 g downwards: F = -m a = +117.7 N up, so the platform is pushed up by 0.235 mm; the
    // command goes that much lower.
    let a = Vector3::new(0.0, 0.0, -8.0 * 9.81);
    let tick = parallel::step(&model, &mut data, &p, &a).unwrap();
    let f = -1.5 * a;
    assert!((tick.load - f).norm() < 1e-12);
    let want = p - Vector3::new(0.0, 0.0, 2e-6 * f.z);
    assert!(
        (tick.commanded - want).norm() < 1e-15,
        "{:?}",
        tick.commanded
    );
    assert!((d.fk(&tick.joints).unwrap() - tick.commanded).norm() < 1e-12);
    // A map of the wrong shape is refused when the corrector is built.
    let flat = GridMap::new(
        vec![vec![0.0, 1.0], vec![0.0, 1.0]],
        ["x", "y"].map(String::from).to_vec(),
        3,
        3,
        vec![0.0; 36],
        vec![0.0; 36],
    )
    .unwrap();
    assert!(Model::new(d, flat, 1.5).is_err());
}
