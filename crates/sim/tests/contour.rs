//! The `contour` scenario on small objects with a coarse step (seconds in a debug build): the
//! tracer closes the loop round a convex and a non-convex object without losing contact for
//! more than a few readings and without reaching the jam force, and the Eq. 10 compensation
//! shrinks the shape error.

use deflect_sim::scenes::contour::{self, ContourRun, ObjectSpec, Outline, TraceOptions};

fn opts() -> TraceOptions {
    TraceOptions {
        step: 2.5e-3,
        approach_step: 2.0e-3,
        bias_samples: 2,
        ..Default::default()
    }
}

fn circle() -> ObjectSpec {
    ObjectSpec {
        name: "small_circle".into(),
        outline: Outline::Circle {
            center: [0.60, 0.0],
            radius: 0.025,
        },
        start: [0.57, 0.0],
    }
}

fn l_shape() -> ObjectSpec {
    ObjectSpec {
        name: "small_l".into(),
        outline: Outline::Polygon {
            vertices: vec![
                [0.55, -0.025],
                [0.60, -0.025],
                [0.60, 0.0],
                [0.575, 0.0],
                [0.575, 0.025],
                [0.55, 0.025],
            ],
        },
        start: [0.544, -0.01],
    }
}

fn check(r: &ContourRun, jam_force: f64) {
    println!(
        "{}: {} in {} steps, {} contacts (eq21 {}), losses {} (longest {}), jams {}, max F {:.2} N \
         (peak {:.1}), path {:.4}/{:.4} m; raw rms {:.4} max {:.4} mm, compensated rms {:.4} max \
         {:.4} mm, {} physics steps in {:.2} s",
        r.name,
        r.state,
        r.tracer_steps,
        r.contacts,
        r.eq21_steps,
        r.contact_losses,
        r.longest_loss,
        r.jams,
        r.max_force,
        r.peak_force,
        r.path_length,
        r.perimeter,
        r.raw.rms_mm,
        r.raw.max_mm,
        r.compensated.rms_mm,
        r.compensated.max_mm,
        r.physics_steps,
        r.wall
    );
    assert_eq!(r.state, "done", "{}: the loop closes", r.name);
    assert!(
        r.path_length > 0.9 * r.perimeter && r.path_length < 1.3 * r.perimeter,
        "{}: went once round",
        r.name
    );
    assert!(r.longest_loss <= 4, "{}: contact lost too long", r.name);
    assert_eq!(r.jams, 0, "{}: jam readings", r.name);
    assert!(
        r.max_force < jam_force,
        "{}: settled force {}",
        r.name,
        r.max_force
    );
    assert!(
        r.raw.rms_mm > 0.5,
        "{}: the drive train distorts the raw shape",
        r.name
    );
    assert!(
        r.compensated.rms_mm < 0.1 * r.raw.rms_mm && r.compensated.max_mm < 0.2 * r.raw.max_mm,
        "{}: compensation shrinks the error: raw {:?} compensated {:?}",
        r.name,
        r.raw,
        r.compensated
    );
}

#[test]
fn traces_a_convex_circle_and_compensation_shrinks_the_error() {
    let o = opts();
    let r = contour::trace(&circle(), &o).unwrap();
    check(&r, o.jam_force);
}

#[test]
fn traces_a_non_convex_l_shape_and_compensation_shrinks_the_error() {
    let o = opts();
    let r = contour::trace(&l_shape(), &o).unwrap();
    check(&r, o.jam_force);
    // Both concave and convex corners were passed: points near every vertex.
    if let Outline::Polygon { vertices } = &r.outline {
        for v in vertices {
            let near = r
                .samples
                .iter()
                .filter_map(|s| s.compensated)
                .any(|p| ((p[0] - v[0]).powi(2) + (p[1] - v[1]).powi(2)).sqrt() < 5.0e-3);
            assert!(near, "no recorded point near vertex {v:?}");
        }
    }
}

#[test]
fn deterministic_and_independent_of_threads() {
    let o = TraceOptions {
        max_steps: 25,
        ..opts()
    };
    let objects = [circle(), l_shape()];
    let a = contour::trace_all(&objects, &o, 1).unwrap();
    let b = contour::trace_all(&objects, &o, 2).unwrap();
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.samples.len(), y.samples.len());
        for (s, t) in x.samples.iter().zip(&y.samples) {
            assert_eq!(s.q_link, t.q_link);
            assert_eq!(s.force_sensed, t.force_sensed);
            assert_eq!(s.compensated, t.compensated);
        }
    }
}
