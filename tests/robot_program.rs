//! URScript out, read back by a parser written here (not the writer's code): the built-in job
//! on the KR 300. Every `movel` pose is the forward kinematics of the compensated joints of a
//! sample (1e-6 m, 1e-6 rad), every sample's commanded TCP lies within the decimation
//! tolerance of the written polyline, the moves' ends stop exactly (`r=0`); every `servoj`
//! holds a sample's compensated joints to 1e-9 rad (all of them, in order).

use deflect_core::io::robot_program;
use deflect_core::machining::job::{self, Job};
use deflect_core::vjm::{self, Data};
use deflect_tests::{JOB_SEED, job_setup, kr300, read_mm as read, repo_path};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

/// The numbers between the first `[` and its `]` of `line`, and the `name=value` pairs after.
fn parse(line: &str) -> (Vec<f64>, Vec<(String, f64)>) {
    let open = line.find('[').unwrap();
    let close = line[open..].find(']').unwrap() + open;
    let numbers = line[open + 1..close]
        .split(',')
        .map(|x| x.trim().parse::<f64>().unwrap())
        .collect();
    let rest = &line[close + 1..line.rfind(')').unwrap()];
    let named = rest
        .split(',')
        .filter_map(|kv| {
            let (k, v) = kv.split_once('=')?;
            Some((k.trim().to_string(), v.trim().parse().unwrap()))
        })
        .collect();
    (numbers, named)
}

#[test]
fn urscript_reads_back_onto_the_compensated_joints() {
    let text = std::fs::read_to_string(repo_path("data/groove_and_pocket.nc")).unwrap();
    let program = read(&text);
    let setup = job_setup(
        Vector2::new(0.005, -0.015),
        Vector2::new(0.085, 0.045),
        5.0e-4,
    );
    let placement = setup.placement;
    let robot = kr300();
    let model = robot.model.clone();
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
    let r = job::run(&job, &program, &JOB_SEED).unwrap();
    let mut data = Data::new(&model);
    let fk = |data: &mut Data, q: &[f64]| vjm::forward(&model, data, q).unwrap();

    // Cartesian: each pose is some sample's FK at its compensated joints.
    let tol = 1.0e-6;
    let script = robot_program::urscript_movel(&r, &placement, tol, 1.2);
    assert!(script.starts_with("def deflect_job():") && script.ends_with("end\ndeflect_job()\n"));
    let mut poses = Vec::new();
    for line in script
        .lines()
        .filter(|l| l.trim_start().starts_with("movel("))
    {
        let (p, named) = parse(line);
        assert_eq!(p.len(), 6);
        let rotation = UnitQuaternion::from_scaled_axis(Vector3::new(p[3], p[4], p[5]));
        let pose = Isometry3::from_parts(Translation3::new(p[0], p[1], p[2]), rotation);
        let blend = named.iter().find(|(k, _)| k == "r").unwrap().1;
        poses.push((pose, blend));
    }
    assert!(
        poses.len() > 20 && poses.len() < r.samples.len() / 4,
        "{}",
        poses.len()
    );
    let samples: Vec<(Isometry3<f64>, &job::JobSample)> = r
        .samples
        .iter()
        .map(|s| (fk(&mut data, &s.q_commanded[..6]), s))
        .collect();
    for (pose, _) in &poses {
        let (best, _) = samples
            .iter()
            .min_by(|a, b| {
                let d =
                    |x: &Isometry3<f64>| (x.translation.vector - pose.translation.vector).norm();
                d(&a.0).total_cmp(&d(&b.0))
            })
            .unwrap();
        assert!((best.translation.vector - pose.translation.vector).norm() < 1e-6);
        assert!(best.rotation.angle_to(&pose.rotation) < 1e-6);
    }
    // Every sample's TCP within the tolerance of the written polyline (rounding aside).
    let polyline: Vec<Vector3<f64>> = poses.iter().map(|(p, _)| p.translation.vector).collect();
    for (tcp, s) in &samples {
        let x = tcp.translation.vector;
        let d = polyline
            .windows(2)
            .map(|w| deflect_core::contour::shape::distance_to_segment(&x, &w[0], &w[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(
            d <= tol * (1.0 + 1e-6) + 1e-12,
            "t = {}: {d:e} m",
            s.path.time
        );
    }
    // The program's exact stops: at least one r=0 per move, the first and last poses among them.
    assert_eq!(poses.first().unwrap().1, 0.0);
    assert_eq!(poses.last().unwrap().1, 0.0);

    // Axis-specific: every sample's compensated joints, in order, to 1e-9 rad.
    let joints = robot_program::urscript_servoj(&r);
    let rows: Vec<Vec<f64>> = joints
        .lines()
        .filter(|l| l.trim_start().starts_with("servoj("))
        .map(|l| parse(l).0)
        .collect();
    assert_eq!(rows.len(), r.samples.len());
    for (row, s) in rows.iter().zip(&r.samples) {
        assert_eq!(row.len(), 6);
        for (a, b) in row.iter().zip(&s.q_commanded[..6]) {
            assert!((a - b).abs() <= 1e-9, "{a} vs {b}");
        }
    }
    assert!(
        joints.contains("# line 8,"),
        "the slot's program line named"
    );
}
