//! The contour tracer's per-tick path allocates nothing: a counting global allocator watches
//! a trace of a few hundred steps (bias, approach, contact, sliding along a wall) through
//! `contour::step` and `Data::set_stiffness`, error paths included. One test function only,
//! so no other test thread allocates meanwhile.

use deflect_core::TickError;
use deflect_core::contour::{self, TracerConfig, TracerState};
use nalgebra::{Matrix2, Vector2};

mod common;

#[global_allocator]
static GLOBAL: common::Counting = common::Counting;

/// The wall: the object fills `x >= WALL_X` \[m\].
const WALL_X: f64 = 0.45;

/// Robot xy stiffness at the commanded position \[N/m\]: diagonal, stiff along x, its y part
/// varying with the pose (so the tracer's stiffness really is updated every tick).
fn stiffness_at(p: &Vector2<f64>) -> Matrix2<f64> {
    Matrix2::new(8000.0, 0.0, 0.0, 3000.0 + 1000.0 * (10.0 * p.y).sin())
}

/// Quasi-static contact of a robot of diagonal stiffness `k` commanded to `p` against the
/// frictionless wall: the tool stops on the wall and slides freely along y, so it pushes with
/// `k_xx * penetration` along +x (the force the tool exerts on the object).
fn wall_force(k: &Matrix2<f64>, p: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(k[(0, 0)] * f64::max(p.x - WALL_X, 0.0), 0.0)
}

#[test]
fn contour_tracer_step_does_not_allocate() {
    common::watch_this_thread();
    common::assert_counter_works();

    let start = Vector2::new(0.4, 0.0);
    let config = TracerConfig::new(1e-3, 2.0, 30.0);
    let model = contour::Model::new(config, &stiffness_at(&start)).unwrap();
    let mut data = contour::Data::new(&model);
    // A constant sensor offset the tracer must learn during Init and remove.
    let bias = Vector2::new(0.3, -0.2);
    let singular = Matrix2::new(1e4, 1e4, 1e4, 1e4);
    let mut p = start;
    let mut first_trace = None;
    let mut contacts_seen = 0usize;
    let mut worst_tool_x = 0.0f64;
    let mut worst_force = 0.0f64;
    let mut last_state = data.state();

    let before = common::allocations();
    for i in 0..600 {
        let k = stiffness_at(&p);
        data.set_stiffness(&k).unwrap();
        let f = wall_force(&k, &p) + bias;
        let out = contour::step(&model, &mut data, &p, &f).unwrap();
        if out.state == TracerState::Trace && first_trace.is_none() {
            first_trace = Some(i);
        }
        if out.contact {
            contacts_seen += 1;
            // Eq. 11 with the exact stiffness puts the estimated tool on the wall, and the
            // bias-removed force is the true contact force.
            worst_tool_x = worst_tool_x.max((out.tool.x - WALL_X).abs());
            worst_force = worst_force.max((out.force - (f - bias)).norm());
        }
        last_state = out.state;
        p = out.command;
        // Error paths allocate nothing either, and leave the tracer as it was.
        assert!(matches!(
            data.set_stiffness(&singular),
            Err(TickError::Singular { .. })
        ));
        assert!(matches!(
            contour::step(&model, &mut data, &Vector2::new(f64::NAN, 0.0), &f),
            Err(TickError::NonFinite { .. })
        ));
    }
    let after = common::allocations();

    // The trace was real: bias learned, wall reached soon after the 10 bias samples and the
    // 50 mm approach, then steady contact while sliding along the wall.
    assert!((data.bias() - bias).norm() < 1e-12, "bias {}", data.bias());
    let first_trace = first_trace.expect("the tracer never reached the Trace state");
    assert!(first_trace < 100, "contact only at step {first_trace}");
    assert_eq!(last_state, TracerState::Trace);
    assert_eq!(data.state(), TracerState::Trace);
    let stats = *data.stats();
    assert_eq!(stats.contacts, contacts_seen);
    assert!(stats.contacts > 400, "contacts {}", stats.contacts);
    assert!(stats.eq21_steps > stats.normal_steps, "{stats:?}");
    assert_eq!(stats.jams, 0, "{stats:?}");
    assert!(
        stats.max_force > config.contact_force && stats.max_force < config.jam_force,
        "{stats:?}"
    );
    let start_tool = data.start().expect("first contact recorded");
    assert!((start_tool.x - WALL_X).abs() < 1e-9, "start {start_tool}");
    assert!(
        worst_tool_x < 1e-9,
        "tool off the wall by {worst_tool_x:e} m"
    );
    assert!(worst_force < 1e-9, "force error {worst_force:e} N");
    // Slid along the wall (counter-clockwise round the object on +x: towards -y), about one
    // step per contact.
    assert!(
        stats.path_length > 0.5 * 1e-3 * stats.contacts as f64,
        "path {}",
        stats.path_length
    );
    assert!(
        (p.y - start_tool.y).abs() > 0.3,
        "moved {} m",
        p.y - start_tool.y
    );

    assert_eq!(after - before, 0, "allocations on the per-tick tracer path");
}
