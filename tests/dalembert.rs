//! The paper's generic D'Alembert corrector (`dalembert::parallel`) with a displacement model
//! of the user's own: the virtual-joint model of a serial arm ([`VjmDisplacement`]).

use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::mechanism::{IkOptions, Mechanism, SerialArm};
use deflect_core::motion::{Limits, Trajectory};
use deflect_core::{ModelBuilder, vjm};
use deflect_tests::VjmDisplacement;
use nalgebra::{Isometry3, SVector, Vector3};

#[test]
fn serial_arm_corrected_with_its_virtual_joint_model() {
    // A 3R arm (z, y, y) with compliant joints, driven along a 3-D line at 3 g.
    let model = ModelBuilder::new()
        .fixed(Isometry3::translation(0.0, 0.0, 0.3))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .spring([2.0e4, 2.0e4, 1.0e4])
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .spring([2.0e4, 5.0e3, 2.0e4])
        .unwrap()
        .fixed(Isometry3::translation(0.5, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::y())
        .unwrap()
        .spring([2.0e4, 4.0e3, 2.0e4])
        .unwrap()
        .fixed(Isometry3::translation(0.4, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let arm = SerialArm::<3>::new(model.clone(), IkOptions::default()).unwrap();
    let vjm_model = VjmDisplacement {
        model: model.clone(),
        moment: Vector3::zeros(),
    };
    let q0 = SVector::<f64, 3>::new(0.2, -0.5, 1.2);
    let start = arm.forward(&mut arm.new_data(), &q0).unwrap();
    let end = start + Vector3::new(0.0, 0.1, -0.05);
    let traj =
        Trajectory::line(start, end, &Limits::new(0.5, 3.0 * 9.81, 2000.0).unwrap()).unwrap();
    let corr = Model::new(arm, vjm_model, 2.0)
        .unwrap()
        .with_fixed_point(10, 1e-12)
        .unwrap();
    let mut corr_data = Data::new(&corr);
    corr_data.set_seed(q0);
    let mut worst: f64 = 0.0;
    let mut largest: f64 = 0.0;
    parallel::correct_each(&corr, &mut corr_data, &traj, 2000.0, |_, t| {
        // The loaded arm commanded to `joints` puts its TCP on the desired point.
        let mut data = vjm::Data::new(&model);
        let w = vjm::Vector6::new(t.load.x, t.load.y, t.load.z, 0.0, 0.0, 0.0);
        let d =
            vjm::deflection(&model, &mut data, t.joints.as_slice(), &w, vjm::Load::Exact).unwrap();
        let reached = data.tcp.translation.vector + Vector3::new(d[0], d[1], d[2]);
        worst = worst.max((reached - t.desired).norm());
        largest = largest.max(t.displacement.norm());
    })
    .unwrap();
    assert!(largest > 1e-5, "the test must load the arm: {largest}");
    assert!(worst < 1e-9, "loaded TCP off the path by {worst} m");
}
