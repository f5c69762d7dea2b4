//! Robot programs out, read back by parsers written here (not the writers' code) on the
//! built-in job (`data/groove_and_pocket.nc` on the KR 300):
//!
//! - every Cartesian target (KRL `LIN` in its `BASE` with its `TOOL`, RAPID `MoveL` in its
//!   work object, URScript `movel` in the base frame, CSV poses) is the forward kinematics
//!   of some sample's compensated joints (1e-6 m, 1e-6 rad), in time order, and every
//!   sample's commanded TCP lies within the decimation tolerance of the written polyline;
//! - every joint target (KRL `PTP` of `E6AXIS`, RAPID `MoveAbsJ`, URScript `servoj`, CSV
//!   rows), turned back by the controller's convention written out here (KUKA: A1, A4, A6
//!   against the URDF's axes; the ABB-style test convention: axes 2 and 3 offset by 90
//!   degrees), equals a sample's compensated joints to 1e-9 rad; `servoj` and the CSV hold
//!   every sample, KRL and RAPID every sample within the joint tolerance of their motion;
//! - the motions stop exactly (no `C_DIS`, `fine`, `r=0`) at the first and last target, and
//!   each program line's first motion is named in a comment.

use std::f64::consts::FRAC_PI_2;

use deflect_core::SerialRobot;
use deflect_core::controller::{Convention, Vendor};
use deflect_core::io::robot_program::{self, Command, Language, ProgramOptions, Target};
use deflect_core::machining::Program;
use deflect_core::machining::job::{self, Job, JobSample, Report};
use deflect_core::vjm::{self, Data};
use deflect_tests::{JOB_SEED, job_setup, kr300, read_mm as read, repo_path};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector2, Vector3};

const TOLERANCE: f64 = 1.0e-6;

struct Run {
    robot: SerialRobot,
    placement: Isometry3<f64>,
    program: Program,
    report: Report,
    /// The FK of every sample's compensated joints, model base frame.
    fk: Vec<Isometry3<f64>>,
}

fn run(robot: SerialRobot) -> Run {
    let text = std::fs::read_to_string(repo_path("data/groove_and_pocket.nc")).unwrap();
    let program = read(&text);
    let setup = job_setup(
        Vector2::new(0.005, -0.015),
        Vector2::new(0.085, 0.045),
        5.0e-4,
    );
    let placement = setup.placement;
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
    let report = job::run(&job, &program, &JOB_SEED).unwrap();
    let mut data = Data::new(&robot.model);
    let fk = report
        .samples
        .iter()
        .map(|s| vjm::forward(&robot.model, &mut data, &s.q_commanded[..6]).unwrap())
        .collect();
    Run {
        robot,
        placement,
        program,
        report,
        fk,
    }
}

fn write(
    r: &Run,
    convention: Option<&Convention>,
    language: Language,
    command: Command,
) -> Vec<(String, String)> {
    let target = Target {
        model: &r.robot.model,
        convention,
        robot: "the KR 300",
        placement: r.placement,
        program: &r.program,
        rate_hz: r.report.rate_hz,
        rapid_speed: 0.25,
    };
    let mut options = ProgramOptions::new(language, command);
    options.tolerance = TOLERANCE;
    options.joint_tolerance = 1.0e-5;
    robot_program::write(target, &r.report.samples, &options)
        .unwrap()
        .into_iter()
        .map(|f| (f.name, f.text))
        .collect()
}

/// The numbers of a comma-separated list.
fn numbers(list: &str) -> Vec<f64> {
    list.split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .unwrap_or_else(|_| panic!("{x:?} in {list:?}"))
        })
        .collect()
}

/// KRL's `{X 1, Y 2, ..., S 2, T 35}` (with or without a type): name -> value.
fn krl_aggregate(text: &str) -> Vec<(String, f64)> {
    let open = text.find('{').unwrap();
    let close = text.rfind('}').unwrap();
    let mut body = &text[open + 1..close];
    if let Some(colon) = body.find(':') {
        body = &body[colon + 1..];
    }
    body.split(',')
        .map(|kv| {
            let mut it = kv.split_whitespace();
            let (k, v) = (it.next().unwrap(), it.next().unwrap());
            (k.to_string(), v.parse().unwrap())
        })
        .collect()
}

fn get(kv: &[(String, f64)], k: &str) -> f64 {
    kv.iter()
        .find(|(n, _)| n == k)
        .unwrap_or_else(|| panic!("{k} in {kv:?}"))
        .1
}

/// A KRL frame: X, Y, Z mm, then Rz(A) Ry(B) Rx(C) in degrees.
fn krl_frame(kv: &[(String, f64)]) -> Isometry3<f64> {
    let r = |d: f64| d.to_radians();
    let rot = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), r(get(kv, "A")))
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), r(get(kv, "B")))
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), r(get(kv, "C")));
    Isometry3::from_parts(
        Translation3::new(
            get(kv, "X") * 1e-3,
            get(kv, "Y") * 1e-3,
            get(kv, "Z") * 1e-3,
        ),
        rot,
    )
}

/// `[[x, y, z], [w, x, y, z]]` (mm) at the start of `text`.
fn rapid_pose(text: &str) -> Isometry3<f64> {
    let inner: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    let parts: Vec<&str> = inner.trim_start_matches('[').split("],[").collect();
    let p = numbers(parts[0]);
    let q = numbers(parts[1].split(']').next().unwrap());
    Isometry3::from_parts(
        Translation3::new(p[0] * 1e-3, p[1] * 1e-3, p[2] * 1e-3),
        UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3])),
    )
}

/// The sample indices the written poses are (each within 1e-6 m / rad of the FK, in order;
/// of the run of samples that match, the nearest: a stop holds nearly equal poses).
fn match_poses(r: &Run, poses: &[Isometry3<f64>]) -> Vec<usize> {
    let mut from = 0;
    let error = |k: usize, p: &Isometry3<f64>| {
        (r.fk[k].translation.vector - p.translation.vector).norm()
            + r.fk[k].rotation.angle_to(&p.rotation)
    };
    poses
        .iter()
        .map(|p| {
            let close = |k: usize| {
                (r.fk[k].translation.vector - p.translation.vector).norm() < 1e-6
                    && r.fk[k].rotation.angle_to(&p.rotation) < 1e-6
            };
            let first = (from..r.fk.len())
                .find(|&k| close(k))
                .unwrap_or_else(|| panic!("no sample from {from} is the pose {p}"));
            let run_end = (first..r.fk.len())
                .take_while(|&k| close(k))
                .last()
                .unwrap_or(first);
            let k = (first..=run_end)
                .min_by(|&a, &b| error(a, p).total_cmp(&error(b, p)))
                .unwrap_or(first);
            from = k;
            k
        })
        .collect()
}

/// Every sample's commanded TCP within the tolerance of the polyline of the kept samples
/// (and at most 256 samples dropped in a row).
fn within_polyline(r: &Run, kept: &[usize]) {
    assert_eq!(kept.first(), Some(&0));
    // The last pose is the last sample's (samples at rest there match the first of them).
    let mut kept = kept.to_vec();
    let last = *kept.last().unwrap();
    for k in last..r.fk.len() {
        let d = (r.fk[k].translation.vector - r.fk[last].translation.vector).norm();
        assert!(
            d < 1e-6,
            "sample {k} of {}: {d:e} m from the last pose",
            r.fk.len()
        );
    }
    kept.push(r.fk.len() - 1);
    for w in kept.windows(2) {
        let (a, b) = (r.fk[w[0]].translation.vector, r.fk[w[1]].translation.vector);
        for k in w[0]..=w[1] {
            let d = deflect_core::contour::shape::distance_to_segment(
                &r.fk[k].translation.vector,
                &a,
                &b,
            );
            assert!(d <= TOLERANCE * (1.0 + 1e-6) + 1e-12, "sample {k}: {d:e} m");
        }
    }
}

/// The joints the written ones are (1e-9 rad), in order; every sample within `tolerance` of
/// the linear motion (in time) between them.
fn match_joints(r: &Run, rows: &[[f64; 6]], tolerance: f64) -> Vec<usize> {
    let samples = &r.report.samples;
    let same =
        |s: &JobSample, q: &[f64; 6]| (0..6).all(|i| (s.q_commanded[i] - q[i]).abs() <= 1e-9);
    let mut from = 0;
    let kept: Vec<usize> = rows
        .iter()
        .map(|q| {
            let k = (from..samples.len())
                .find(|&k| same(&samples[k], q))
                .unwrap_or_else(|| panic!("no sample from {from} has the joints {q:?}"));
            from = k;
            k
        })
        .collect();
    for w in kept.windows(2) {
        let (a, b) = (&samples[w[0]], &samples[w[1]]);
        for s in &samples[w[0]..=w[1]] {
            let t = (s.path.time - a.path.time) / (b.path.time - a.path.time).max(1e-300);
            for i in 0..6 {
                let lerp = a.q_commanded[i] + (b.q_commanded[i] - a.q_commanded[i]) * t;
                assert!((lerp - s.q_commanded[i]).abs() <= tolerance * (1.0 + 1e-9) + 1e-12);
            }
        }
    }
    kept
}

#[test]
fn krl_reads_back_onto_the_compensated_joints() {
    let r = run(kr300());
    let c = r.robot.controller.unwrap();
    let files = write(&r, Some(&c), Language::Krl, Command::Cartesian);
    assert_eq!(files[0].0, "deflect_job.src");
    assert_eq!(files[1].0, "deflect_job.dat");
    let (src, dat) = (&files[0].1, &files[1].1);
    assert!(src.starts_with("&ACCESS RVP\n&REL 1\nDEF deflect_job( )") && src.ends_with("END\n"));
    assert!(dat.contains("DEFDAT deflect_job PUBLIC") && dat.trim_end().ends_with("ENDDAT"));
    let decl = |name: &str| {
        let line = dat
            .lines()
            .find(|l| l.starts_with(&format!("DECL FRAME {name}=")))
            .unwrap();
        krl_frame(&krl_aggregate(line))
    };
    let (base, tool) = (decl("DEFLECT_BASE"), decl("DEFLECT_TOOL"));
    assert!((base.translation.vector - r.placement.translation.vector).norm() < 1e-9);
    assert!(base.rotation.angle_to(&r.placement.rotation) < 1e-9);
    assert!((tool.translation.vector - Vector3::new(0.12, 0.0, 0.31)).norm() < 1e-9);
    assert!(src.contains("$BASE = DEFLECT_BASE") && src.contains("$TOOL = DEFLECT_TOOL"));
    let mut poses = Vec::new();
    let mut blends = Vec::new();
    for line in src.lines().filter(|l| l.starts_with("LIN ")) {
        let kv = krl_aggregate(line);
        poses.push(base * krl_frame(&kv));
        blends.push(line.trim_end().ends_with("C_DIS"));
        let (s, t) = (get(&kv, "S"), get(&kv, "T"));
        // The tool down over the table in front: basic area, wrist in front, A5 < 0 here
        // (the seed's -0.5 rad), so S = 6; T: A2 < 0 (2), A5 < 0 (16), and A1, A4, A6 as
        // their signs come.
        assert_eq!(s, 6.0, "{line}");
        assert!(t as u32 & 0b10010 == 0b10010, "{line}");
    }
    assert!(
        poses.len() > 20 && poses.len() < r.fk.len() / 4,
        "{}",
        poses.len()
    );
    // The CL pose in the base frame = FLANGE * TOOL: the controller's TCP; the written
    // poses in BASE composed with BASE are the FK of the compensated joints.
    let kept = match_poses(&r, &poses);
    within_polyline(&r, &kept);
    assert!(!blends[0] && !blends[blends.len() - 1]);
    assert!(blends.iter().any(|b| *b) && blends.iter().filter(|b| !**b).count() >= 4);
    assert!(src.contains("$VEL.CP = 0.025") && src.contains("$APO.CDIS = 0.001"));
    assert!(src.contains("; line 8,"), "the slot's program line named");
    // The first motion: a PTP to the first sample's joints in KUKA's axes.
    let ptp = src.lines().find(|l| l.starts_with("PTP ")).unwrap();
    let kv = krl_aggregate(ptp);
    let sign = [-1.0, 1.0, 1.0, -1.0, 1.0, -1.0];
    for (i, s) in sign.iter().enumerate() {
        let a = get(&kv, &format!("A{}", i + 1)).to_radians();
        assert!((s * a - r.report.samples[0].q_commanded[i]).abs() < 1e-9);
    }

    // Axis-specific: PTP of E6AXIS, KUKA's signs.
    let files = write(&r, Some(&c), Language::Krl, Command::Joints);
    let rows: Vec<[f64; 6]> = files[0]
        .1
        .lines()
        .filter(|l| l.starts_with("PTP "))
        .skip(1)
        .map(|l| {
            let kv = krl_aggregate(l);
            std::array::from_fn(|i| sign[i] * get(&kv, &format!("A{}", i + 1)).to_radians())
        })
        .collect();
    let kept = match_joints(&r, &rows, 1.0e-5);
    assert_eq!(kept.first(), Some(&0));
    assert!(*kept.last().unwrap() >= r.fk.len() - 3, "the end at rest");
    assert!(rows.len() < r.fk.len() / 2, "{}", rows.len());
}

/// The KR 300 with an ABB-style controller convention (see the module docs).
fn abb_robot() -> (SerialRobot, [f64; 6]) {
    let toml =
        std::fs::read_to_string(repo_path("robots/kr300/kr300_r2500_stiffness.toml")).unwrap();
    let springs = &toml[..toml.find("[controller]").unwrap()];
    let abb = format!(
        "{springs}[controller]\nvendor = \"abb\"\njoint_sign = [1, 1, 1, 1, 1, 1]\n\
         joint_offset = [0, {FRAC_PI_2}, {}, 0, 0, 0]\nflange = \"ft_sensor\"\n",
        -FRAC_PI_2
    );
    let urdf = std::fs::read_to_string(repo_path("robots/kr300/kr300_r2500.urdf")).unwrap();
    let robot = SerialRobot::from_str(&urdf, &abb, None, "tcp").unwrap();
    (robot, [0.0, FRAC_PI_2, -FRAC_PI_2, 0.0, 0.0, 0.0])
}

#[test]
fn rapid_reads_back_onto_the_compensated_joints() {
    let (robot, offset) = abb_robot();
    let c = robot.controller.unwrap();
    assert_eq!(c.vendor, Vendor::Abb);
    let r = run(robot);
    let files = write(&r, Some(&c), Language::Rapid, Command::Cartesian);
    assert_eq!(files.len(), 1);
    assert_eq!(files[0].0, "deflect_job.mod");
    let m = &files[0].1;
    assert!(m.starts_with("MODULE deflect_job") && m.trim_end().ends_with("ENDMODULE"));
    let wobj_line = m
        .lines()
        .find(|l| l.contains("PERS wobjdata wobj_deflect"))
        .unwrap();
    let wobj = rapid_pose(&wobj_line[wobj_line.find("\"\",").unwrap() + 3..]);
    assert!((wobj.translation.vector - r.placement.translation.vector).norm() < 1e-9);
    let tool_line = m
        .lines()
        .find(|l| l.contains("PERS tooldata tool_deflect"))
        .unwrap();
    let tool = rapid_pose(&tool_line[tool_line.find("[TRUE,").unwrap() + 6..]);
    assert!((tool.translation.vector - Vector3::new(0.12, 0.0, 0.31)).norm() < 1e-9);
    let mut poses = Vec::new();
    let mut zones = Vec::new();
    for line in m.lines().map(str::trim).filter(|l| l.starts_with("MoveL ")) {
        let body = &line["MoveL ".len()..];
        poses.push(wobj * rapid_pose(body));
        // [[x,y,z],[q],[cf1,cf4,cf6,cfx],[9E9 x6]],speed,zone,tool\WObj
        let conf = body.split("],[").nth(2).unwrap();
        let conf = numbers(conf);
        // Tool down in front, axis 5 negative (the seed's -0.5 rad): cfx = 1.
        assert_eq!(conf[3], 1.0, "{line}");
        let rest = &body[body.find("9E9]],").unwrap() + 6..];
        let speed_end = rest.find(']').unwrap();
        let speed = numbers(&rest[1..speed_end]);
        assert_eq!(speed.len(), 4);
        assert!(speed[0] > 0.0);
        let zone = &rest[speed_end + 2..];
        zones.push(zone.starts_with("fine"));
    }
    let kept = match_poses(&r, &poses);
    within_polyline(&r, &kept);
    assert!(zones[0] && zones[zones.len() - 1] && zones.iter().any(|z| !z));
    assert!(
        m.contains("[25.0000,500,5000,1000]"),
        "25 mm/s of the program's F1500"
    );
    assert!(m.contains("    ! line 8,"));

    let files = write(&r, Some(&c), Language::Rapid, Command::Joints);
    let rows: Vec<[f64; 6]> = files[0]
        .1
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("MoveAbsJ "))
        .skip(1)
        .map(|l| {
            let a = numbers(&l["MoveAbsJ [[".len()..l.find("],[9E9").unwrap()]);
            std::array::from_fn(|i| a[i].to_radians() - offset[i])
        })
        .collect();
    let kept = match_joints(&r, &rows, 1.0e-5);
    assert!(*kept.last().unwrap() >= r.fk.len() - 3, "the end at rest");
}

#[test]
fn urscript_and_csv_read_back_onto_the_compensated_joints() {
    let robot = kr300();
    let ur = Convention::identity(Vendor::UniversalRobots, &robot.model).unwrap();
    let r = run(robot);
    let files = write(&r, Some(&ur), Language::UrScript, Command::Cartesian);
    assert_eq!(files[0].0, "deflect_job.script");
    let script = &files[0].1;
    assert!(script.starts_with("def deflect_job():") && script.ends_with("end\ndeflect_job()\n"));
    let bracket = |l: &str| numbers(&l[l.find('[').unwrap() + 1..l.find(']').unwrap()]);
    let tcp = bracket(script.lines().find(|l| l.contains("set_tcp(")).unwrap());
    assert!(
        tcp.iter().all(|v| *v == 0.0),
        "the identity convention's TCP is the flange"
    );
    let mut poses = Vec::new();
    let mut radii = Vec::new();
    for line in script
        .lines()
        .filter(|l| l.trim_start().starts_with("movel("))
    {
        let p = bracket(line);
        let rotation = UnitQuaternion::from_scaled_axis(Vector3::new(p[3], p[4], p[5]));
        poses.push(Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            rotation,
        ));
        let r_word = line.rsplit("r=").next().unwrap().trim_end_matches(')');
        radii.push(r_word.parse::<f64>().unwrap());
    }
    let kept = match_poses(&r, &poses);
    within_polyline(&r, &kept);
    assert!(radii[0] == 0.0 && *radii.last().unwrap() == 0.0 && radii.iter().any(|x| *x > 0.0));
    let files = write(&r, Some(&ur), Language::UrScript, Command::Joints);
    let rows: Vec<[f64; 6]> = files[0]
        .1
        .lines()
        .filter(|l| l.trim_start().starts_with("servoj("))
        .map(|l| {
            let q = bracket(l);
            std::array::from_fn(|i| q[i])
        })
        .collect();
    assert_eq!(rows.len(), r.fk.len(), "servoj at every sample");
    for (row, s) in rows.iter().zip(&r.report.samples) {
        assert!(
            (0..6).all(|i| (row[i] - s.q_commanded[i]).abs() <= 1e-9),
            "{row:?}"
        );
    }

    // CSV needs no convention: poses in the base frame, joints at every sample.
    let files = write(&r, None, Language::Csv, Command::Cartesian);
    let poses: Vec<Isometry3<f64>> = files[0]
        .1
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time_s"))
        .map(|l| {
            let v = numbers(l);
            Isometry3::from_parts(
                Translation3::new(v[2], v[3], v[4]),
                UnitQuaternion::from_quaternion(Quaternion::new(v[5], v[6], v[7], v[8])),
            )
        })
        .collect();
    within_polyline(&r, &match_poses(&r, &poses));
    let files = write(&r, None, Language::Csv, Command::Joints);
    let rows: Vec<[f64; 6]> = files[0]
        .1
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time_s"))
        .map(|l| {
            let v = numbers(l);
            std::array::from_fn(|i| v[2 + i])
        })
        .collect();
    assert_eq!(rows.len(), r.fk.len());
    for (row, s) in rows.iter().zip(&r.report.samples) {
        assert!(
            (0..6).all(|i| (row[i] - s.q_commanded[i]).abs() <= 1e-12),
            "{row:?}"
        );
    }
}

#[test]
fn a_program_without_its_controller_or_with_bad_options_is_refused_by_name() {
    let r = run(kr300());
    let target = |c| Target {
        model: &r.robot.model,
        convention: c,
        robot: "the KR 300",
        placement: r.placement,
        program: &r.program,
        rate_hz: 250.0,
        rapid_speed: 0.25,
    };
    let samples = &r.report.samples[..10];
    let options = ProgramOptions::new(Language::Rapid, Command::Cartesian);
    let e = robot_program::write(target(None), samples, &options).unwrap_err();
    assert!(
        e.to_string()
            .contains("the KR 300 has no controller convention"),
        "{e}"
    );
    let kuka = r.robot.controller.unwrap();
    let e = robot_program::write(target(Some(&kuka)), samples, &options).unwrap_err();
    assert!(e.to_string().contains("kuka's (KRL)"), "{e}");
    assert!(
        Language::from_name("krl2")
            .unwrap_err()
            .to_string()
            .contains("\"krl2\"")
    );
    assert!(Command::from_name("both").is_err());
    for (tolerance, name) in [
        (0.0, "deflect_job"),
        (f64::NAN, "deflect_job"),
        (1e-6, "9job"),
        (1e-6, "job-1"),
    ] {
        let mut o = ProgramOptions::new(Language::Csv, Command::Cartesian);
        o.tolerance = tolerance;
        o.name = name.to_string();
        assert!(
            robot_program::write(target(None), samples, &o).is_err(),
            "{tolerance} {name}"
        );
    }
}
