//! Stiffness-optimal posture on the shipped KR 300: the refined optimum agrees with a fine
//! scan at 0.1 degree around the coarse best (a check of the refinement, made with the sweep
//! itself: the coarse optimum and the IK branch are checked independently in Python,
//! `test_atlas.py::test_sweep_best_agrees_with_an_independent_full_turn_scan`), every reported
//! posture reaches the task, and unreachable angles are reported as such (NaN, never a zero
//! deflection).

use deflect_core::SerialRobot;
use deflect_core::TickError;
use deflect_core::posture::{self, AnglePoint, Measure, PostureOptions, Reach};
use deflect_core::vjm::{self, Data, Vector6};
use nalgebra::{Unit, Vector3};

mod fixtures;

const Q0: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
/// The milling wrench of the VJM paper's test (Hähn and Weigold, sec. 3): 386.1 N in -x and
/// +y, 60 N in -z.
const WRENCH: [f64; 6] = [-386.1, 386.1, -60.0, 0.0, 0.0, 0.0];

/// The task of the posture Q0: its TCP position and tool (z) axis.
fn task(robot: &SerialRobot) -> (Vector3<f64>, Vector3<f64>) {
    let t = vjm::forward(&robot.model, &mut Data::new(&robot.model), &Q0).unwrap();
    (t.translation.vector, t.rotation * Vector3::z())
}

fn degrees(from: f64, to: f64, step: f64) -> Vec<f64> {
    let n = ((to - from) / step).round() as usize;
    (0..=n)
        .map(|k| (from + k as f64 * step).to_radians())
        .collect()
}

fn run(
    robot: &SerialRobot,
    position: &Vector3<f64>,
    axis: &Vector3<f64>,
    angles: &[f64],
    options: &PostureOptions,
) -> (Vec<AnglePoint>, posture::SweepSummary) {
    let mut data = Data::new(&robot.model);
    let mut out = vec![AnglePoint::default(); angles.len()];
    let s = posture::sweep(
        &robot.model,
        &mut data,
        &robot.joint_limits,
        position,
        axis,
        &Vector6::from_column_slice(&WRENCH),
        angles,
        &Q0,
        options,
        &mut out,
    )
    .unwrap();
    (out, s)
}

#[test]
fn the_refined_optimum_agrees_with_a_brute_scan_at_a_tenth_of_a_degree() {
    let robot = fixtures::kr300();
    let (p, z) = task(&robot);
    let coarse = degrees(-90.0, 90.0, 5.0);
    let (out, s) = run(&robot, &p, &z, &coarse, &PostureOptions::default());
    assert!(s.reachable > 20, "{} reachable", s.reachable);
    let best = s.best.unwrap();
    let sampled = out[s.best_index.unwrap()];
    assert!(best.measure <= sampled.measure);
    // Brute force: 0.1 degree over the bracket the refinement searched, no refinement.
    let centre = sampled.angle.to_degrees();
    let fine = degrees(centre - 5.0, centre + 5.0, 0.1);
    let plain = PostureOptions {
        refine: false,
        ..PostureOptions::default()
    };
    let (scan, _) = run(&robot, &p, &z, &fine, &plain);
    let brute = scan
        .iter()
        .filter(|a| a.reach == Reach::Reachable)
        .min_by(|a, b| a.measure.total_cmp(&b.measure))
        .unwrap();
    assert!(
        (best.angle - brute.angle).abs() <= 0.1f64.to_radians() + 1e-9,
        "refined {} deg, brute {} deg",
        best.angle.to_degrees(),
        brute.angle.to_degrees()
    );
    assert!(best.measure <= brute.measure + 1e-12);
    // The worst reachable angle deflects more, and the spread is worth choosing for.
    let worst = out[s.worst_index.unwrap()];
    assert!(
        worst.measure > 1.05 * best.measure,
        "{} vs {}",
        worst.measure,
        best.measure
    );
}

#[test]
fn every_posture_reaches_the_task_and_its_deflection_is_the_models() {
    let robot = fixtures::kr300();
    let (p, z) = task(&robot);
    let (out, _) = run(
        &robot,
        &p,
        &z,
        &degrees(-60.0, 60.0, 10.0),
        &PostureOptions::default(),
    );
    let mut data = Data::new(&robot.model);
    for a in out.iter().filter(|a| a.reach == Reach::Reachable) {
        let q = &a.q[..6];
        let t = vjm::forward(&robot.model, &mut data, q).unwrap();
        assert!((t.translation.vector - p).norm() < 1e-7);
        assert!((t.rotation * Vector3::z() - z).norm() < 1e-7);
        // Its x axis is the convention's, turned by the angle.
        let want = posture::tool_orientation(&Unit::new_normalize(z), a.angle);
        assert!(t.rotation.angle_to(&want) < 1e-7);
        let d = vjm::deflection(
            &robot.model,
            &mut data,
            q,
            &Vector6::from_column_slice(&WRENCH),
            vjm::Load::Exact,
        )
        .unwrap();
        assert_eq!(d, a.deflection);
        assert_eq!(a.measure, d.fixed_rows::<3>(0).norm());
        for (v, (lo, hi)) in q.iter().zip(&robot.joint_limits) {
            assert!(lo <= v && v <= hi);
        }
    }
}

#[test]
fn measures_by_hand() {
    let d = Vector6::new(3e-4, -4e-4, 1e-4, 1e-3, 0.0, 0.0);
    assert!((Measure::Norm.of(&d) - (26e-8f64).sqrt()).abs() < 1e-18);
    assert_eq!(Measure::Max.of(&d), 4e-4);
    let along =
        Measure::along(&[Vector3::new(2.0, 0.0, 0.0), Vector3::new(0.0, 0.0, -1.0)]).unwrap();
    assert_eq!(along.of(&d), 3e-4);
    assert!(Measure::along(&[]).is_none());
    assert!(Measure::along(&[Vector3::zeros()]).is_none());
}

#[test]
fn unreachable_angles_are_reported_never_as_zeros() {
    let robot = fixtures::kr300();
    let (_, z) = task(&robot);
    let far = Vector3::new(10.0, 0.0, 1.0);
    let (out, s) = run(
        &robot,
        &far,
        &z,
        &degrees(-30.0, 30.0, 10.0),
        &PostureOptions::default(),
    );
    assert_eq!(s.reachable, 0);
    assert_eq!((s.status, s.beyond_model), (Reach::OutOfReach, 0));
    assert!(s.best.is_none() && s.best_index.is_none() && s.worst_index.is_none());
    for a in &out {
        assert_eq!(a.reach, Reach::OutOfReach);
        assert!(a.measure.is_nan() && a.deflection.iter().all(|v| v.is_nan()));
    }
    // Joint limits pinned around Q0's wrist: turning the tool needs the wrist, so most
    // angles are refused as joint-limit violations, the original one stays.
    let mut pinned = fixtures::kr300();
    pinned.joint_limits[5] = (Q0[5] - 0.01, Q0[5] + 0.01);
    pinned.joint_limits[3] = (Q0[3] - 0.01, Q0[3] + 0.01);
    let (p, z) = task(&pinned);
    let (out, s) = run(
        &pinned,
        &p,
        &z,
        &degrees(-180.0, 175.0, 5.0),
        &PostureOptions::default(),
    );
    assert!(out.iter().any(|a| a.reach == Reach::JointLimit));
    assert!(
        s.reachable >= 1 && s.reachable < out.len() / 2,
        "{}",
        s.reachable
    );
}

/// The sweep at Q0's task under `wrench` over `angles`.
fn sweep_under(wrench: [f64; 6], angles: &[f64]) -> (Vec<AnglePoint>, posture::SweepSummary) {
    let robot = fixtures::kr300();
    let (p, z) = task(&robot);
    let mut data = Data::new(&robot.model);
    let mut out = vec![AnglePoint::default(); angles.len()];
    let s = posture::sweep(
        &robot.model,
        &mut data,
        &robot.joint_limits,
        &p,
        &z,
        &Vector6::from_column_slice(&wrench),
        angles,
        &Q0,
        &PostureOptions::default(),
        &mut out,
    )
    .unwrap();
    (out, s)
}

#[test]
fn an_overload_is_beyond_the_model_not_out_of_reach() {
    // 1e12 N: every angle has a posture, the springs would turn by far more than
    // MAX_SPRING_ANGLE. Reported as such, with NaN (never a deflection), and the point's
    // status says the task is in reach.
    let angles = degrees(-30.0, 30.0, 10.0);
    let (out, s) = sweep_under([1e12, 0.0, 0.0, 0.0, 0.0, 0.0], &angles);
    assert_eq!(s.reachable, 0);
    assert_eq!(s.beyond_model, angles.len());
    assert_eq!(s.status, Reach::BeyondModel);
    assert!(s.best.is_none());
    for a in &out {
        assert_eq!(a.reach, Reach::BeyondModel);
        assert!(a.measure.is_nan() && a.deflection.iter().all(|v| v.is_nan()));
    }
    // The same task under the paper's wrench: every angle reachable, none beyond.
    let (_, s) = sweep_under(WRENCH, &angles);
    assert_eq!((s.reachable, s.beyond_model), (angles.len(), 0));
    assert_eq!(s.status, Reach::Reachable);
    // Codes and names are stable (the atlas archives store the codes).
    let named: Vec<(u8, &str)> = Reach::ALL.iter().map(|r| (r.code(), r.name())).collect();
    assert_eq!(
        named,
        [
            (0, "reachable"),
            (1, "out_of_reach"),
            (2, "singular"),
            (3, "joint_limit"),
            (4, "beyond_model")
        ]
    );
}

#[test]
fn bad_inputs_are_statuses() {
    let robot = fixtures::kr300();
    let (p, z) = task(&robot);
    let mut data = Data::new(&robot.model);
    let w = Vector6::from_column_slice(&WRENCH);
    let mut out = vec![AnglePoint::default(); 4];
    let o = PostureOptions::default();
    let angles = [0.0, 0.1, 0.2, 0.3];
    let call = |data: &mut Data,
                axis: &Vector3<f64>,
                seeds: &[f64],
                angles: &[f64],
                out: &mut [AnglePoint]| {
        posture::sweep(
            &robot.model,
            data,
            &robot.joint_limits,
            &p,
            axis,
            &w,
            angles,
            seeds,
            &o,
            out,
        )
    };
    assert!(matches!(
        call(&mut data, &Vector3::zeros(), &Q0, &angles, &mut out),
        Err(TickError::InvalidArgument { .. })
    ));
    assert!(matches!(
        call(&mut data, &z, &Q0[..5], &angles, &mut out),
        Err(TickError::WrongLength { what: "seeds", .. })
    ));
    assert!(matches!(
        call(&mut data, &z, &Q0, &[0.0, f64::NAN, 0.2, 0.3], &mut out),
        Err(TickError::NonFinite { .. })
    ));
    assert!(matches!(
        call(&mut data, &z, &Q0, &angles, &mut out[..2]),
        Err(TickError::WrongLength { what: "output", .. })
    ));
    let too_many = vec![0.0; posture::MAX_ANGLES + 1];
    let mut big = vec![AnglePoint::default(); too_many.len()];
    assert!(matches!(
        call(&mut data, &z, &Q0, &too_many, &mut big),
        Err(TickError::WrongLength { what: "angles", .. })
    ));
}
