//! Process forces and inertia in one machining job: the path's curvature is 1/r on an arc;
//! in air the job's compensated joints, its payload wrench and its inertial deflection are
//! the serial D'Alembert corrector's on the same planned motion (one model, two call paths);
//! an inertia that counts nothing leaves the job bit for bit; bad masses and inertias are
//! typed errors.

mod fixtures;

use deflect_core::BuildError;
use deflect_core::dalembert::serial::{self, Payload};
use deflect_core::machining::job::{self, Inertia, Setup};
use deflect_core::motion::PoseState;
use deflect_core::vjm::{self, Data};
use nalgebra::{Isometry3, Matrix3, Translation3, Vector3};

use fixtures::mm_program as program;

use fixtures::kr300_job;

/// A 60 kg spindle and tool, its centre of mass 0.2 m behind the tip.
fn spindle() -> Payload {
    Payload {
        mass: 60.0,
        com: Vector3::new(0.0, 0.0, -0.2),
        inertia: Matrix3::from_diagonal(&Vector3::new(0.9, 0.9, 0.2)),
    }
}

/// Lines and a full circle of 10 mm radius, 5 mm above the stock's top, at 3 m/min.
const AIR: &str = "G0 X-10 Y0 Z5\nG1 X20 F3000\nG2 X20 Y0 I10\nG1 X40 Y10\n";

#[test]
fn an_arcs_curvature_is_one_over_its_radius_towards_its_centre() {
    let p = program("G0 X10 Y0 Z0\nG2 X10 Y0 I5 F600\n");
    let arc = &p.moves[1];
    for s in [0.0, 0.13, 0.5, 0.77, 1.0] {
        let k = arc.curvature(s);
        let to_centre = Vector3::new(0.015, 0.0, 0.0) - arc.point(s);
        // 1 / 5 mm, along the radius inwards.
        assert!((k.norm() - 200.0).abs() < 1e-6 * 200.0, "{s}: {}", k.norm());
        assert!((k.normalize() - to_centre.normalize()).norm() < 1e-8, "{s}");
    }
    assert_eq!(p.moves[0].curvature(0.5), Vector3::zeros());
}

#[test]
fn in_air_the_jobs_inertial_part_is_the_serial_correctors() {
    let (job, q0) = kr300_job();
    let robot = fixtures::kr300();
    let payload = spindle();
    let job = job
        .with_inertia(Inertia {
            payload,
            links: true,
        })
        .unwrap();
    let p = program(AIR);
    let r = job::run(&job, &p, &q0).unwrap();
    let corrector = serial::Model::new(robot.model.clone(), payload)
        .unwrap()
        .with_joint_limits(&robot.joint_limits)
        .unwrap()
        .with_link_inertia(true);
    let mut data = serial::Data::new(&corrector);
    data.set_seed(&q0);
    let placement = job.setup().placement;
    let (mut worst_q, mut worst_d, mut largest) = (0.0f64, 0.0f64, 0.0f64);
    let mut check = Data::new(&robot.model);
    for s in &r.samples {
        // The planned motion by hand: the feed along the tangent, on the circle (line 3,
        // centre (30, 0) mm, radius 10 mm) v^2 / r towards the centre.
        let path = &s.path;
        let mut a = path.direction * path.acceleration;
        if path.line == 3 {
            let inward = Vector3::new(0.03, 0.0, path.position.z) - path.position;
            a += inward.normalize() * (path.speed * path.speed / 0.01);
        }
        let target = placement
            * Isometry3::from_parts(Translation3::from(path.position), Setup::tool_down());
        let state = PoseState {
            t: path.time,
            pose: target,
            velocity: placement.rotation * (path.direction * path.speed),
            acceleration: placement.rotation * a,
            angular_velocity: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        };
        let tick = serial::step(&corrector, &mut data, &state, None).unwrap();
        // The payload's wrench: the same Eq. 3-5 (the curvature by difference against the
        // closed form: 1e-10 relative).
        let dw = (tick.load - s.inertial_wrench).norm();
        assert!(dw <= 1e-7 * tick.load.norm().max(1.0), "{dw}");
        // The compensated joints: both land the loaded tip on the target, each to the IK's
        // 1e-8 m, so their rigid poses agree to twice that.
        let job_command = vjm::forward(&robot.model, &mut check, &s.q_commanded[..6]).unwrap();
        let dq = (job_command.translation.vector - tick.commanded.translation.vector).norm();
        worst_q = worst_q.max(dq);
        // The inertial deflection at the rigid joints against the corrector's displacement
        // at its command.
        let di = s.deflection_inertial.fixed_rows::<3>(0).norm();
        let dt = tick.displacement.fixed_rows::<3>(0).norm();
        worst_d = worst_d.max((di - dt).abs());
        largest = largest.max(dt);
        // No cutting in air: the compensated prediction is on the program.
        assert!((s.actual_compensated - path.position).norm() < 1e-8);
        assert_eq!(s.force, Vector3::zeros());
    }
    assert!(largest > 1e-6, "the motion loads the arm: {largest}");
    assert!(worst_q < 2e-8, "commanded poses: {worst_q} m");
    // The corrector's displacement is at its command, the job's inertial part at the rigid
    // joints a deflection away: they agree to the deflection's relative size squared.
    assert!(worst_d < 1e-3 * largest, "{worst_d} of {largest}");
    // The report's split: the inertial part per line, the peak acceleration on the circle.
    let circle = r.summary.lines().into_iter().find(|l| l.line == 3).unwrap();
    assert!(circle.deflection_inertial > 1e-6);
    assert_eq!(circle.deflection_process, 0.0);
    let v = 0.05;
    assert!(
        circle.peak_acceleration >= v * v / 0.01 * (1.0 - 1e-6),
        "{}",
        circle.peak_acceleration
    );
}

#[test]
fn an_inertia_that_counts_nothing_leaves_the_job_bit_for_bit() {
    let (job, q0) = kr300_job();
    let p = program("G0 X-10 Y0 Z5\nS13000 M3\nG1 Z-2 F1500\nX40\nG2 X60 Y0 I10\nG0 Z5\n");
    let plain = job::run(&job, &p, &q0).unwrap();
    let zero = job
        .clone()
        .with_inertia(Inertia {
            payload: Payload::point(0.0, Vector3::new(0.0, 0.0, -0.2)),
            links: false,
        })
        .unwrap();
    assert!(zero.inertia().is_none());
    let same = job::run(&zero, &p, &q0).unwrap();
    assert_eq!(plain.samples.len(), same.samples.len());
    for (a, b) in plain.samples.iter().zip(&same.samples) {
        assert_eq!(a.q_commanded, b.q_commanded);
        assert_eq!(a.actual_compensated, b.actual_compensated);
        assert_eq!(a.actual_uncompensated, b.actual_uncompensated);
        assert_eq!(a.deflection_inertial, b.deflection_inertial);
    }
    // A real spindle moves the compensated joints and splits the deflection.
    let heavy = job
        .with_inertia(Inertia {
            payload: spindle(),
            links: false,
        })
        .unwrap();
    let r = job::run(&heavy, &p, &q0).unwrap();
    let moved = r
        .samples
        .iter()
        .zip(&plain.samples)
        .map(|(a, b)| (a.q_commanded[0] - b.q_commanded[0]).abs())
        .fold(0.0f64, f64::max);
    assert!(moved > 1e-9, "{moved}");
    let line4 = r.summary.lines().into_iter().find(|l| l.line == 4).unwrap();
    assert!(line4.deflection_process > 1e-5 && line4.deflection_inertial > 0.0);
    // Both parts in one prediction: the compensated tool stays on the program.
    assert!(r.path_error(true).max < 1e-6, "{:?}", r.path_error(true));
}

#[test]
fn bad_masses_and_inertias_are_typed_errors() {
    let (job, _) = kr300_job();
    let with = |payload: Payload| {
        job.clone().with_inertia(Inertia {
            payload,
            links: true,
        })
    };
    let e = with(Payload::point(-1.0, Vector3::zeros())).unwrap_err();
    assert!(
        matches!(e, BuildError::InvalidParameter { what: "payload mass", value, .. } if value == -1.0),
        "{e:?}"
    );
    let e = with(Payload::point(f64::NAN, Vector3::zeros())).unwrap_err();
    assert!(
        matches!(
            e,
            BuildError::InvalidParameter {
                what: "payload mass",
                ..
            }
        ),
        "{e:?}"
    );
    let mut p = spindle();
    p.inertia = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 5.0));
    let e = with(p).unwrap_err();
    assert!(
        matches!(e, BuildError::InvalidParameter { value, .. } if (value - 3.0).abs() < 1e-9),
        "{e:?}"
    );
    p.inertia = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -0.5));
    assert!(matches!(with(p).unwrap_err(), BuildError::Singular { .. }));
    p.inertia = Matrix3::identity();
    p.com.x = f64::INFINITY;
    assert!(matches!(
        with(p).unwrap_err(),
        BuildError::NonFinite {
            what: "payload com",
            index: 0
        }
    ));
}
