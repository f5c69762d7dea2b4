//! The drive-train correction and the contour tracer step allocate nothing: a counting
//! global allocator watches many calls. One test function only, so no other test thread
//! allocates meanwhile.

use deflect_core::contour::{self, TracerConfig};
use deflect_core::drivetrain::{
    self, Data, LinkMasses, cartesian_stiffness, cartesian_stiffness_xy, compensated_forward,
    gravity_torques,
};
use deflect_core::{ModelBuilder, TickError};
use nalgebra::{Isometry3, Matrix2, Vector2, Vector3, Vector6};

mod common;
mod fixtures;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

#[test]
fn drive_train_and_tracer_do_not_allocate() {
    common::watch_this_thread();
    common::assert_counter_works();
    let b = fixtures::six_r(fixtures::Link::Rigid);
    let mut masses = LinkMasses::new();
    for i in 0..6 {
        masses
            .push(i, 10.0 - i as f64, Vector3::new(0.1, 0.0, 0.02))
            .unwrap();
    }
    let model = b.build().unwrap();
    let drive = drivetrain::Model::new(model, &[1e5; 6], &[1e-4; 6])
        .unwrap()
        .with_masses(masses)
        .unwrap();
    let planar = ModelBuilder::new()
        .revolute(Vector3::z())
        .unwrap()
        .fixed(Isometry3::translation(0.5, 0.0, 0.0))
        .unwrap()
        .revolute(Vector3::z())
        .unwrap()
        .fixed(Isometry3::translation(0.4, 0.0, 0.0))
        .unwrap()
        .build()
        .unwrap();
    let pdrive = drivetrain::Model::new(planar, &[2000.0, 1000.0], &[0.0; 2]).unwrap();
    let mut data = Data::new(&drive);
    let mut pdata = Data::new(&pdrive);
    let wrench = Vector6::new(30.0, -20.0, -50.0, 1.0, 0.0, -0.5);
    let mut q = [0.1, -0.4, 0.9, 0.2, 0.6, -0.3];
    let k = Matrix2::new(8000.0, 500.0, 500.0, 3000.0);
    let tracer = contour::Model::new(TracerConfig::new(1e-3, 2.0, 30.0), &k).unwrap();
    let mut tracer_data = contour::Data::new(&tracer);
    let mut p = Vector2::new(0.4, 0.0);
    let mut sink = 0.0;

    let before = common::allocations();
    for i in 0..3_000 {
        q[0] = 1e-4 * i as f64;
        sink += gravity_torques(&drive, &mut data, &q).unwrap()[1];
        sink += drivetrain::step(&drive, &mut data, &q, &wrench).unwrap().q[2];
        sink += compensated_forward(&drive, &mut data, &q, &wrench)
            .unwrap()
            .translation
            .x;
        sink += cartesian_stiffness(&drive, &mut data, &q).unwrap()[(0, 0)];
        sink += cartesian_stiffness_xy(&pdrive, &mut pdata, &[q[0], 1.2]).unwrap()[(0, 0)];
        sink += contour::edge_direction(&k, &Vector2::new(1e-3, 2e-4), &Vector2::new(0.0, 1.0))
            .unwrap();
        // A wall at x = 0.45: the tracer approaches, then slides along it.
        let f = Vector2::new(f64::max(p.x - 0.45, 0.0) * 8000.0, 0.0);
        let out = contour::step(&tracer, &mut tracer_data, &p, &f).unwrap();
        p = out.command;
        tracer_data.set_stiffness(&k).unwrap();
        // Error paths allocate nothing either.
        let bad = drivetrain::step(&drive, &mut data, &q[..5], &wrench);
        assert!(matches!(bad, Err(TickError::WrongLength { .. })));
        assert!(
            contour::step(&tracer, &mut tracer_data, &Vector2::new(f64::NAN, 0.0), &f).is_err()
        );
    }
    let after = common::allocations();
    assert!(sink.is_finite());
    assert!(tracer_data.stats().contacts > 100, "the tracer did trace");
    assert_eq!(after - before, 0, "allocations on the per-call path");
}
