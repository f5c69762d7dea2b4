//! Joint correction of the virtual-joint model (VJM paper, sec. 2.2): the deflected TCP lands
//! on the target, least squares where the arm cannot, singular poses reported.

use approx::assert_relative_eq;
use deflect_core::vjm::{self, Data, Vector6};
use deflect_core::{ModelBuilder, TickError};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

mod fixtures;

fn w(f: [f64; 6]) -> Vector6 {
    Vector6::from_row_slice(&f)
}

#[test]
fn joint_correction_lands_the_deflected_tcp_on_target() {
    // Torsion springs coaxial with the joints: the deflected arm is the rigid arm with angles
    // q + dq + gamma, so dq = -gamma(q + dq) cancels position and orientation exactly.
    let model = fixtures::planar_2r();
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
    let axes = fixtures::SIX_R_AXES;
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
    let cmd = vjm::commanded_pose(&target, &d).unwrap();
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
