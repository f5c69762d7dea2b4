//! The `contour` scenario: tracing closes round convex and non-convex objects and Eq. 10
//! compensation shrinks the shape error.

use deflect_sim::contour_scene::{self, ContourRun, ObjectSpec, Outline, TraceOptions};

fn show(r: &ContourRun) {
    println!(
        "{}: {} in {} steps, {} contacts (eq21 {} normal {}), losses {} longest {}, jams {}, shortened {}, max F {:.2} N peak {:.2} N, path {:.4}/{:.4} m\n  raw rms {:.4} max {:.4} | comp rms {:.4} max {:.4} | actual rms {:.4} max {:.4} mm; {} physics steps in {:.2} s",
        r.name, r.state, r.tracer_steps, r.contacts, r.eq21_steps, r.normal_steps, r.contact_losses, r.longest_loss, r.jams, r.shortened, r.max_force, r.peak_force, r.path_length, r.perimeter,
        r.raw.rms_mm, r.raw.max_mm, r.compensated.rms_mm, r.compensated.max_mm, r.actual.rms_mm, r.actual.max_mm, r.physics_steps, r.wall
    );
}

#[test]
#[ignore]
fn explore_defaults() {
    let opts = TraceOptions::default();
    for o in contour_scene::default_objects() {
        let r = contour_scene::trace(&o, &opts).unwrap();
        show(&r);
    }
}

#[test]
#[ignore]
fn explore_debug() {
    let mut opts = TraceOptions::default();
    opts.max_steps = 60;
    let o = &contour_scene::default_objects()[0];
    let r = contour_scene::trace(o, &opts);
    match r {
        Ok(r) => { for s in r.samples.iter().take(80) { println!("{:?}", s); } show(&r); }
        Err(e) => println!("{e}"),
    }
}

#[test]
#[ignore]
fn explore_worst() {
    let opts = TraceOptions::default();
    for o in contour_scene::default_objects() {
        let r = contour_scene::trace(&o, &opts).unwrap();
        show(&r);
        let mut v: Vec<(f64, usize)> = r.samples.iter().enumerate().filter_map(|(i, s)| s.compensated.map(|c| (o.outline.distance(&nalgebra::Vector2::new(c[0], c[1])), i))).collect();
        v.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (d, i) in v.iter().take(4) {
            let s = &r.samples[*i];
            let tq: Vec<f64> = (0..2).map(|k| s.q_motor[k] - s.q_link[k]).collect();
            println!("  {i}: {:.4} mm, F {:?} Ftrue {:?} dq {:?} state {}", d * 1e3, s.force, s.force_true, tq, s.state);
        }
    }
}
