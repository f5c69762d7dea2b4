//! Contour tracing (section 3 of the contour-tracking paper): Eq. 21 against the force model
//! of Eq. 16-20, and the tracer of Figures 3-4 driving a simulated planar 2R arm with
//! compliant, backlashed joints around a circle, a rectangle and a non-convex L-shape, with
//! shape recovery from raw joint readings vs readings compensated by Eq. 10.

use deflect_core::contour::shape::{self, ShapeError};
use deflect_core::contour::{self, TraceDirection, TracerConfig, TracerState};
use deflect_core::drivetrain::{self, Data, cartesian_stiffness_xy};
use deflect_core::{BuildError, ModelBuilder, TickError};
use nalgebra::{Isometry3, Matrix2, Vector2, Vector3, Vector6};

/// xorshift64*: deterministic test randomness.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * std::f64::consts::PI);
    d.min(2.0 * std::f64::consts::PI - d)
}

#[test]
fn eq21_recovers_the_edge_angle_for_random_stiffness_and_edges() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut worst = 0.0f64;
    let mut n = 0;
    while n < 20_000 {
        // Random SPD K: A A^T + small diagonal, 1e2 .. 1e6 N/m.
        let a = Matrix2::from_fn(|_, _| rng.uniform(-1.0, 1.0)) * 10f64.powf(rng.uniform(1.0, 3.0));
        let k = a * a.transpose() + Matrix2::identity() * 10f64.powf(rng.uniform(2.0, 4.0));
        let edge = rng.uniform(-std::f64::consts::PI, std::f64::consts::PI);
        let theta1 = rng.uniform(-std::f64::consts::PI, std::f64::consts::PI);
        if (edge - theta1).cos().abs() < 0.05 {
            continue; // pushing (almost) straight into the edge: no motion along it
        }
        let r = rng.uniform(1e-4, 5e-3);
        let step = Vector2::new(r * theta1.cos(), r * theta1.sin());
        let f = contour::edge_contact_force(&k, &step, edge).unwrap();
        // Eq. 11 says the same: the tool stopped at the projected point.
        let f11 = contour::contact_force(&k, &step, &contour::edge_motion(&step, edge));
        assert!((f - f11).norm() <= 1e-12 * f.norm().max(1.0));
        let est = contour::edge_direction(&k, &step, &f).unwrap();
        // The direction of motion along the edge: theta_2 or theta_2 + pi.
        let expect = if (edge - theta1).cos() > 0.0 {
            edge
        } else {
            edge + std::f64::consts::PI
        };
        worst = worst.max(angle_diff(est, expect));
        n += 1;
    }
    println!("Eq. 21: worst edge-angle error over {n} random cases: {worst:e} rad");
    assert!(worst < 1e-9, "worst {worst:e}");
}

#[test]
fn eq21_errors() {
    let k = Matrix2::new(1e4, 0.0, 0.0, 2e4);
    let step = Vector2::new(1e-3, 0.0);
    // Straight into a vertical edge: the tool does not move.
    let f = contour::edge_contact_force(&k, &step, std::f64::consts::FRAC_PI_2).unwrap();
    assert_eq!(
        contour::edge_direction(&k, &step, &f),
        Err(TickError::NoEdgeMotion)
    );
    let singular = Matrix2::new(1e4, 1e4, 1e4, 1e4);
    assert!(matches!(
        contour::edge_direction(&singular, &step, &f),
        Err(TickError::Singular { .. })
    ));
    assert!(matches!(
        contour::edge_direction(&k, &Vector2::new(f64::NAN, 0.0), &f),
        Err(TickError::NonFinite { .. })
    ));
    // Bad configurations.
    let mut cfg = TracerConfig::new(1e-3, 5.0, 2.0);
    assert!(matches!(
        contour::Model::new(cfg, &k),
        Err(BuildError::InvalidParameter {
            what: "jam_force",
            ..
        })
    ));
    cfg = TracerConfig::new(1e-3, 2.0, 20.0);
    cfg.approach_direction = Vector2::zeros();
    assert!(contour::Model::new(cfg, &k).is_err());
    let tm = contour::Model::new(TracerConfig::new(1e-3, 2.0, 20.0), &k).unwrap();
    let mut t = contour::Data::new(&tm);
    assert!(t.set_stiffness(&singular).is_err());
    assert!(
        contour::step(
            &tm,
            &mut t,
            &Vector2::new(0.0, f64::INFINITY),
            &Vector2::zeros()
        )
        .is_err()
    );
    assert_eq!(t.state(), TracerState::Init);
}

/// A planar 2R arm in the xy plane whose joints have stiffness and backlash; the motors hold
/// the commanded angles (position control), the links sit where the contact lets them.
struct Arm {
    l: [f64; 2],
    k: [f64; 2],
    backlash: [f64; 2],
    drive: drivetrain::Model,
}

impl Arm {
    fn new() -> Self {
        let l = [0.5, 0.4];
        let k = [2000.0, 1000.0];
        let backlash = [2.0e-4, 3.0e-4];
        let model = ModelBuilder::new()
            .revolute(Vector3::z())
            .unwrap()
            .fixed(Isometry3::translation(l[0], 0.0, 0.0))
            .unwrap()
            .revolute(Vector3::z())
            .unwrap()
            .fixed(Isometry3::translation(l[1], 0.0, 0.0))
            .unwrap()
            .build()
            .unwrap();
        let drive = drivetrain::Model::new(model, &k, &backlash).unwrap();
        Self {
            l,
            k,
            backlash,
            drive,
        }
    }
    fn fk(&self, q: &[f64; 2]) -> Vector2<f64> {
        let (a, b) = (q[0], q[0] + q[1]);
        Vector2::new(
            self.l[0] * a.cos() + self.l[1] * b.cos(),
            self.l[0] * a.sin() + self.l[1] * b.sin(),
        )
    }
    fn jac(&self, q: &[f64; 2]) -> Matrix2<f64> {
        let (a, b) = (q[0], q[0] + q[1]);
        Matrix2::new(
            -self.l[0] * a.sin() - self.l[1] * b.sin(),
            -self.l[1] * b.sin(),
            self.l[0] * a.cos() + self.l[1] * b.cos(),
            self.l[1] * b.cos(),
        )
    }
    fn ik(&self, p: &Vector2<f64>) -> [f64; 2] {
        let [l1, l2] = self.l;
        let c2 = ((p.norm_squared() - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
        let q2 = c2.acos();
        let q1 = p.y.atan2(p.x) - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
        [q1, q2]
    }
}

enum Shape {
    Circle(Vector2<f64>, f64),
    Polygon(Vec<Vector2<f64>>),
}

impl Shape {
    /// Boundary distance.
    fn distance(&self, p: &Vector2<f64>) -> f64 {
        match self {
            Shape::Circle(c, r) => shape::distance_to_circle(p, c, *r),
            Shape::Polygon(v) => shape::distance_to_polygon(p, v),
        }
    }
    /// For points inside: (depth d, unit gradient u of d, i.e. into the object, Hessian of
    /// d), d being the distance to the boundary.
    fn penetration(&self, p: &Vector2<f64>) -> Option<(f64, Vector2<f64>, Matrix2<f64>)> {
        match self {
            Shape::Circle(c, r) => {
                let d = p - c;
                let n = d.norm();
                let u = -d / n;
                (n < *r).then(|| (r - n, u, -(Matrix2::identity() - u * u.transpose()) / n))
            }
            Shape::Polygon(v) => {
                if !shape::inside_polygon(p, v) {
                    return None;
                }
                // Nearest boundary point.
                let mut best = (f64::INFINITY, Vector2::zeros(), false);
                for i in 0..v.len() {
                    let (a, b) = (v[i], v[(i + 1) % v.len()]);
                    let ab = b - a;
                    let t_raw = (p - a).dot(&ab) / ab.norm_squared();
                    let t = t_raw.clamp(0.0, 1.0);
                    let q = a + ab * t;
                    let d = (p - q).norm();
                    if d < best.0 {
                        best = (d, q, t != t_raw);
                    }
                }
                let (d, q, at_vertex) = best;
                let u = (p - q) / d;
                // Distance to a vertex curves (|p - v|); to an edge it is flat.
                let h = if at_vertex {
                    (Matrix2::identity() - u * u.transpose()) / d
                } else {
                    Matrix2::zeros()
                };
                (d > 0.0).then_some((d, u, h))
            }
        }
    }
}

/// Contact stiffness of the rigid object [N/m] (penalty).
const K_CONTACT: f64 = 1.0e7;

/// Quasi-static equilibrium of the arm with motors at `q_cmd` against `shape`, reached from
/// the previous link angles `q_from` (the tool slides on from where it was): the link angles
/// and the force the tool exerts on the object. Minimizes spring + contact energy by Newton
/// with a line search; the backlash is taken up in the direction of the joint torque.
fn equilibrium(
    arm: &Arm,
    shape: &Shape,
    q_cmd: &[f64; 2],
    q_from: &[f64; 2],
) -> ([f64; 2], Vector2<f64>) {
    let mut sgn = [0.0f64; 2];
    let mut q = *q_from;
    let mut force = Vector2::zeros();
    for _ in 0..6 {
        let q_ref = [
            q_cmd[0] - sgn[0] * arm.backlash[0],
            q_cmd[1] - sgn[1] * arm.backlash[1],
        ];
        let energy = |q: &[f64; 2]| {
            let spring: f64 = (0..2)
                .map(|i| 0.5 * arm.k[i] * (q[i] - q_ref[i]).powi(2))
                .sum();
            let contact = shape
                .penetration(&arm.fk(q))
                .map_or(0.0, |(d, _, _)| 0.5 * K_CONTACT * d * d);
            spring + contact
        };
        for _ in 0..200 {
            let j = arm.jac(&q);
            let kd = Matrix2::new(arm.k[0], 0.0, 0.0, arm.k[1]);
            let dq = Vector2::new(q[0] - q_ref[0], q[1] - q_ref[1]);
            let (mut g, mut h) = (kd * dq, kd);
            if let Some((d, u, hd)) = shape.penetration(&arm.fk(&q)) {
                g += j.transpose() * u * (K_CONTACT * d);
                h += j.transpose() * (u * u.transpose() + hd * d) * j * K_CONTACT;
            }
            if g.norm() < 1e-10 {
                break;
            }
            let step = -h.try_inverse().unwrap() * g;
            let e0 = energy(&q);
            let mut alpha = 1.0;
            let mut next = [q[0] + step[0], q[1] + step[1]];
            while energy(&next) > e0 - 1e-4 * alpha * g.dot(&step).abs() && alpha > 1e-9 {
                alpha *= 0.5;
                next = [q[0] + alpha * step[0], q[1] + alpha * step[1]];
            }
            let moved = (alpha * step).norm();
            q = next;
            if moved < 1e-15 {
                break;
            }
        }
        force = shape
            .penetration(&arm.fk(&q))
            .map_or(Vector2::zeros(), |(d, u, _)| u * (K_CONTACT * d));
        let u = arm.jac(&q).transpose() * force;
        let residual = (0..2)
            .map(|i| (arm.k[i] * (q[i] - q_ref[i]) + u[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(
            residual < 1e-4,
            "equilibrium not found: residual {residual:e} N m"
        );
        let new_sgn = [
            u[0].signum() * (u[0] != 0.0) as u8 as f64,
            u[1].signum() * (u[1] != 0.0) as u8 as f64,
        ];
        if new_sgn == sgn {
            break;
        }
        sgn = new_sgn;
    }
    (q, force)
}

struct TraceResult {
    state: TracerState,
    stats: deflect_core::contour::TracerStats,
    raw: ShapeError,
    compensated: ShapeError,
    truth: ShapeError,
    max_true_force: f64,
    steps: usize,
}

fn trace(shape: &Shape, start: Vector2<f64>, noise: f64) -> TraceResult {
    let arm = Arm::new();
    let mut data = Data::new(&arm.drive);
    let bias = Vector2::new(0.7, -0.4);
    let mut rng = Rng(12345);
    // The arm is up to ~4 times stiffer along x than along y here: a tool that wraps round
    // a corner can trade the soft direction for the stiff one and its force jumps, so the
    // target force sits well inside the window.
    let mut cfg = TracerConfig::new(1.5e-3, 1.5, 30.0);
    cfg.target_force = 6.0;
    cfg.approach_step = 1.0e-3;
    cfg.direction = TraceDirection::CounterClockwise;
    let q0 = arm.ik(&start);
    let k0 = cartesian_stiffness_xy(&arm.drive, &mut data, &q0).unwrap();
    let tracer_model = contour::Model::new(cfg, &k0).unwrap();
    let mut tracer = contour::Data::new(&tracer_model);
    let mut cmd = start;
    let mut q_prev = q0;
    let (mut raw, mut comp, mut truth) = (Vec::new(), Vec::new(), Vec::new());
    let mut max_true_force = 0.0f64;
    let mut steps = 0;
    let state = loop {
        steps += 1;
        let q_cmd = arm.ik(&cmd);
        let (q_true, f) = equilibrium(&arm, shape, &q_cmd, &q_prev);
        q_prev = q_true;
        max_true_force = max_true_force.max(f.norm());
        let sensed =
            f + bias + Vector2::new(rng.uniform(-noise, noise), rng.uniform(-noise, noise));
        let k = cartesian_stiffness_xy(&arm.drive, &mut data, &q_cmd).unwrap();
        tracer.set_stiffness(&k).unwrap();
        let out = contour::step(&tracer_model, &mut tracer, &cmd, &sensed).unwrap();
        if out.contact {
            // The motor readings are the commanded angles.
            raw.push(arm.fk(&q_cmd));
            let w = Vector6::new(out.force.x, out.force.y, 0.0, 0.0, 0.0, 0.0);
            let c = drivetrain::step(&arm.drive, &mut data, &q_cmd, &w).unwrap();
            comp.push(arm.fk(&[c.q[0], c.q[1]]));
            truth.push(arm.fk(&q_true));
        }
        if out.state.is_finished() || steps > 20_000 {
            break out.state;
        }
        cmd = out.command;
    };
    let d = |p: &Vector2<f64>| shape.distance(p);
    TraceResult {
        state,
        stats: *tracer.stats(),
        raw: shape::shape_error(&raw, d),
        compensated: shape::shape_error(&comp, d),
        truth: shape::shape_error(&truth, d),
        max_true_force,
        steps,
    }
}

fn check(name: &str, shape: &Shape, start: Vector2<f64>, perimeter: f64) {
    let r = trace(shape, start, 0.05);
    println!(
        "{name}: {:?} after {} steps; {} contacts, eq21 {} / normal {} / bisections {} / shortened {} / jams {}, \
         longest loss {}, max force {:.1} N (sensed {:.1}), path {:.4} m (perimeter {:.4})\n  \
         raw rms {:.3} mm max {:.3} mm | compensated rms {:.4} mm max {:.4} mm | true tool rms {:.4} mm",
        r.state,
        r.steps,
        r.stats.contacts,
        r.stats.eq21_steps,
        r.stats.normal_steps,
        r.stats.bisections,
        r.stats.shortened,
        r.stats.jams,
        r.stats.longest_loss,
        r.max_true_force,
        r.stats.max_force,
        r.stats.path_length,
        perimeter,
        r.raw.rms * 1e3,
        r.raw.max * 1e3,
        r.compensated.rms * 1e3,
        r.compensated.max * 1e3,
        r.truth.rms * 1e3,
    );
    assert_eq!(r.state, TracerState::Done, "{name}");
    // Went all the way round (the estimated path is a bit longer than the perimeter).
    assert!(
        r.stats.path_length > 0.95 * perimeter && r.stats.path_length < 1.3 * perimeter,
        "{name}: path {}",
        r.stats.path_length
    );
    assert!(
        r.stats.longest_loss <= 3,
        "{name}: lost contact for {} steps",
        r.stats.longest_loss
    );
    assert!(
        r.max_true_force < 30.0,
        "{name}: force {}",
        r.max_true_force
    );
    assert!(
        r.stats.eq21_steps > r.stats.normal_steps,
        "{name}: Eq. 21 mostly used"
    );
    // Eq. 10 compensation shrinks the error by an order of magnitude at least; what is left
    // is the sensor noise through K^-1, second-order terms and the contact penetration.
    assert!(
        r.compensated.rms < 20e-6 && r.compensated.max < 50e-6,
        "{name}"
    );
    assert!(r.raw.rms > 0.5e-3, "{name}: raw error should be visible");
    assert!(
        r.compensated.rms < 0.1 * r.raw.rms && r.compensated.max < 0.2 * r.raw.max,
        "{name}: raw {:?} vs compensated {:?}",
        r.raw,
        r.compensated
    );
}

#[test]
fn traces_a_circle() {
    let c = Vector2::new(0.6, 0.05);
    check(
        "circle",
        &Shape::Circle(c, 0.08),
        Vector2::new(0.45, 0.05),
        2.0 * std::f64::consts::PI * 0.08,
    );
}

#[test]
fn traces_a_rectangle_with_sharp_corners() {
    let v = vec![
        Vector2::new(0.5, -0.05),
        Vector2::new(0.7, -0.05),
        Vector2::new(0.7, 0.07),
        Vector2::new(0.5, 0.07),
    ];
    check(
        "rectangle",
        &Shape::Polygon(v),
        Vector2::new(0.45, 0.0),
        0.64,
    );
}

#[test]
fn traces_a_non_convex_l_shape() {
    let v = vec![
        Vector2::new(0.5, -0.06),
        Vector2::new(0.7, -0.06),
        Vector2::new(0.7, 0.0),
        Vector2::new(0.6, 0.0),
        Vector2::new(0.6, 0.08),
        Vector2::new(0.5, 0.08),
    ];
    check(
        "L-shape",
        &Shape::Polygon(v),
        Vector2::new(0.45, 0.01),
        0.68,
    );
}

#[test]
fn traces_clockwise_and_reports_failures() {
    // Clockwise round the circle closes as well.
    let arm = Arm::new();
    let shape = Shape::Circle(Vector2::new(0.6, 0.05), 0.08);
    let mut data = Data::new(&arm.drive);
    let mut cfg = TracerConfig::new(1.5e-3, 2.0, 30.0);
    cfg.direction = TraceDirection::Clockwise;
    cfg.bias_samples = 1;
    let mut cmd = Vector2::new(0.45, 0.05);
    let k = cartesian_stiffness_xy(&arm.drive, &mut data, &arm.ik(&cmd)).unwrap();
    let tracer_model = contour::Model::new(cfg, &k).unwrap();
    let mut tracer = contour::Data::new(&tracer_model);
    let mut state = tracer.state();
    let mut q_prev = arm.ik(&cmd);
    for _ in 0..5000 {
        let q = arm.ik(&cmd);
        let (q_true, f) = equilibrium(&arm, &shape, &q, &q_prev);
        q_prev = q_true;
        let k = cartesian_stiffness_xy(&arm.drive, &mut data, &q).unwrap();
        tracer.set_stiffness(&k).unwrap();
        let out = contour::step(&tracer_model, &mut tracer, &cmd, &f).unwrap();
        state = out.state;
        if state.is_finished() {
            break;
        }
        cmd = out.command;
    }
    assert_eq!(state, TracerState::Done);
    assert_eq!(state.name(), "done");
    // Finished tracers hold the position.
    let out = contour::step(&tracer_model, &mut tracer, &cmd, &Vector2::zeros()).unwrap();
    assert_eq!(out.command, cmd);

    // Nothing to touch: the approach gives up.
    let mut cfg = TracerConfig::new(1e-3, 2.0, 30.0);
    cfg.bias_samples = 1;
    cfg.max_approach_steps = 50;
    let tm = contour::Model::new(cfg, &k).unwrap();
    let mut t = contour::Data::new(&tm);
    let mut p = Vector2::zeros();
    for _ in 0..60 {
        p = contour::step(&tm, &mut t, &p, &Vector2::zeros())
            .unwrap()
            .command;
    }
    assert_eq!(t.state().name(), "failed_no_contact");

    // The object vanishes after contact: bisections run out.
    let mut t = contour::Data::new(&tm);
    let _bias = contour::step(&tm, &mut t, &p, &Vector2::zeros()).unwrap();
    let out = contour::step(&tm, &mut t, &p, &Vector2::new(10.0, 0.0)).unwrap();
    assert!(out.contact);
    let mut state = out.state;
    for _ in 0..20 {
        state = contour::step(&tm, &mut t, &out.command, &Vector2::zeros())
            .unwrap()
            .state;
    }
    assert_eq!(state.name(), "failed_contact_lost");

    // A force that stays above the jam force.
    let mut t = contour::Data::new(&tm);
    let _bias = contour::step(&tm, &mut t, &p, &Vector2::zeros()).unwrap();
    let mut state = t.state();
    for _ in 0..20 {
        state = contour::step(&tm, &mut t, &p, &Vector2::new(100.0, 0.0))
            .unwrap()
            .state;
    }
    assert_eq!(state.name(), "failed_jammed");
}
