//! The five-axis pass and the predicted part in 3-D: a tilted floor's deviation along its
//! normal from a cut offset along it (hand-derived: the offset), the swarf cut on the KR 300
//! (the compensated tool on the program's tip and axis to the IK's tolerance, checked by the
//! VJM again; the uncompensated one off by the deflection), the flat slot's force against the
//! z-map job's (Altintas' closed form there) and bad input.

mod fixtures;

use deflect_core::JobError;
use deflect_core::io::apt;
use deflect_core::io::gcode::GcodeOptions;
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::dexel::surface::{DeviationStats, Face, SurfaceMesh};
use deflect_core::machining::dexel::{DexelTool, Dexels};
use deflect_core::machining::five_axis::{self, Options};
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::profile::{Profile, ToolShape};
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::vjm::{self, Data};
use nalgebra::{Isometry3, Translation3, Vector2, Vector3};

#[test]
fn a_tilted_floor_cut_deeper_along_its_normal_deviates_by_the_offset() {
    let cell = 0.5e-3;
    let block = || {
        Dexels::block(
            Vector3::new(0.0, -0.02, -0.02),
            Vector3::new(0.04, 0.02, 0.0),
            cell,
        )
        .unwrap()
    };
    let t = Tool::new(0.016, 3, 0.0).unwrap();
    let tool = DexelTool::new(&Profile::new(&t, ToolShape::Flat).unwrap(), 0.03).unwrap();
    // The axis tilted 30 degrees about x: the end face sweeps a plane strip with normal a.
    let (s, c) = 30f64.to_radians().sin_cos();
    let a = Vector3::new(0.0, -s, c);
    let (from, to) = (
        Vector3::new(0.005, 0.0, -0.006),
        Vector3::new(0.035, 0.0, -0.006),
    );
    let delta = 2.0e-5;
    let mut nominal = block();
    let mut deeper = block();
    let _ = nominal.cut(&tool, &from, &a, &to, &a).unwrap();
    let _ = deeper
        .cut(&tool, &(from - a * delta), &a, &(to - a * delta), &a)
        .unwrap();
    let (points, missing) = nominal.surface_deviation(&deeper, 2.0 * cell).unwrap();
    assert_eq!(missing, 0);
    // On the strip, away from its edges: the normal is a and the deviation -delta.
    let strip: Vec<_> = points
        .iter()
        .filter(|p| {
            let r = p.position - from;
            let across = r - Vector3::x() * r.x;
            r.dot(&a).abs() < 1e-9
                && across.norm() < 0.008 - 3.0 * cell
                && (0.005 + 2.0 * cell..0.035 - 2.0 * cell).contains(&p.position.x)
        })
        .collect();
    assert!(strip.len() > 200, "{}", strip.len());
    for p in &strip {
        assert!((p.normal - a).norm() < 1e-9, "{:?}", p.normal);
        assert!((p.deviation + delta).abs() < 1e-12, "{}", p.deviation);
        assert_eq!(Face::of(p), Face::PlusZ);
    }
    // The same cut on both: no deviation anywhere.
    let (same, _) = nominal
        .surface_deviation(&nominal.clone(), 2.0 * cell)
        .unwrap();
    assert_eq!(DeviationStats::of(&same).max_abs(), 0.0);
    // The mesh joins the strip's points: about two triangles per point.
    let strip_count = strip.len();
    let mesh = SurfaceMesh::new(points, cell).unwrap();
    assert!(
        mesh.triangles.len() > strip_count,
        "{}",
        mesh.triangles.len()
    );
    // Each triangle is wound with its vertices' outward normal.
    for t in &mesh.triangles {
        let [p, q, r] = t.map(|k| mesh.points[k as usize]);
        let face = (q.position - p.position).cross(&(r.position - p.position));
        assert!(face.dot(&(p.normal + q.normal + r.normal)) >= 0.0);
    }
    // Blocks that differ are refused.
    let other = Dexels::block(Vector3::zeros(), Vector3::repeat(0.01), cell).unwrap();
    assert!(nominal.surface_deviation(&other, 2.0 * cell).is_err());
    assert!(nominal.surface_deviation(&deeper, f64::NAN).is_err());
}

/// The KR 300 holding the tool down over a table at its first pose.
fn kr300_job(cell: f64) -> (Job, Vec<f64>) {
    let robot = fixtures::kr300();
    let q0 = vec![0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];
    let tcp = vjm::forward(&robot.model, &mut Data::new(&robot.model), &q0).unwrap();
    let rotation = tcp.rotation * Setup::tool_down().inverse();
    let origin = tcp.translation.vector - rotation * Vector3::new(0.0, 0.0, 0.02);
    let setup = Setup {
        placement: Isometry3::from_parts(Translation3::from(origin), rotation),
        tool_orientation: Setup::tool_down(),
        tool: Tool::new(0.016, 3, 0.0).unwrap(),
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min: Vector2::new(0.0, -0.03),
            max: Vector2::new(0.08, 0.03),
            top: 0.0,
            cell,
        },
        path: PathOptions::default(),
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: job::RAPID_SKIM,
    };
    (
        Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap(),
        q0,
    )
}

fn read(text: &str) -> deflect_core::machining::Program {
    apt::from_str(text, &GcodeOptions::default())
        .unwrap()
        .program
}

/// A swarf cut: the tool tilted 15 degrees away from the wall at y = -0.022 it cuts with its
/// flank and its end 3 mm deep, along x.
const SWARF: &str = "UNITS/MM\nSPINDL/12000,CLW\nRAPID\nGOTO/-12,-22,20,0,0,1\nRAPID\n\
    GOTO/-12,-22,5,0,-0.2588190,0.9659258\nFEDRAT/MMPM,1200\nGOTO/-12,-22,-3,0,-0.2588190,0.9659258\n\
    GOTO/60,-22,-3,0,-0.2588190,0.9659258\nGOTO/60,-22,10,0,0,1\nFINI\n";

#[test]
fn the_compensated_swarf_cut_holds_the_program_tip_and_axis() {
    let (job, seed) = kr300_job(1.0e-3);
    let program = read(SWARF);
    assert!(program.is_multi_axis());
    let r = five_axis::run(&job, &program, &seed, &Options::default()).unwrap();
    let cutting = r.samples.iter().filter(|s| s.bands > 0).count();
    assert!(cutting > 100, "{cutting}");
    let unc = r.errors(false);
    let comp = r.errors(true);
    // The arm bends by tenths of a millimetre and milliradians under the cut...
    assert!(unc.max_position > 5.0e-5, "{unc:?}");
    assert!(unc.max_axis > 1.0e-5, "{unc:?}");
    // ... and the compensated tool stays on the tip and the axis to the IK's tolerances (the
    // deflected pose evaluated again by the VJM).
    let ik = job.setup().ik;
    assert!(comp.max_position <= ik.position_tolerance, "{comp:?}");
    assert!(comp.max_axis <= ik.orientation_tolerance, "{comp:?}");
    // The force lies in the tool's frame as the model has it: the flank pushes the tool away
    // from the wall (+y) and the feed pushes back (-x).
    let mid = r
        .samples
        .iter()
        .find(|s| s.bands > 0 && (s.path.position.x - 0.024).abs() < 2e-4)
        .unwrap();
    assert!(mid.force.norm() > 50.0, "{:?}", mid.force);
    // The predicted parts along the surface's normal: the compensated one on the program's to
    // the IK's tolerance, the uncompensated one off by the deflection.
    let (pu, _) = r
        .nominal
        .surface_deviation(&r.uncompensated, 3.0e-3)
        .unwrap();
    let (pc, _) = r.nominal.surface_deviation(&r.compensated, 3.0e-3).unwrap();
    let (su, sc) = (DeviationStats::of(&pu), DeviationStats::of(&pc));
    assert!(su.max_abs() > 2.0e-5, "{su:?}");
    assert!(sc.max_abs() < ik.position_tolerance, "{sc:?}");
    assert!(su.count > 1000 && sc.count > 1000, "{su:?} {sc:?}");
}

#[test]
fn a_flat_slot_feels_the_z_map_jobs_force() {
    // The same slot through both passes: the 2.5-D job's force is Altintas' closed form for
    // slotting (tests/machining_job.rs); the five-axis pass reads it from the dexels along the
    // edge.
    let (job, seed) = kr300_job(5.0e-4);
    let text = "UNITS/MM\nSPINDL/12000,CLW\nRAPID\nGOTO/-12,0,5\nFEDRAT/MMPM,1200\n\
                GOTO/-12,0,-4\nGOTO/60,0,-4\nGOTO/60,0,10\nFINI\n";
    let program = read(text);
    let flat = job::run(&job, &program, &seed).unwrap();
    let five = five_axis::run(&job, &program, &seed, &Options::default()).unwrap();
    let pick = |x: f64| {
        let a = flat
            .samples
            .iter()
            .find(|s| (s.path.position.x - x).abs() < 1e-4 && s.path.feed_move)
            .unwrap();
        let b = five
            .samples
            .iter()
            .find(|s| s.path.time == a.path.time)
            .unwrap();
        (a.force, b.force)
    };
    let (a, b) = pick(0.03);
    assert!(a.norm() > 100.0, "{a:?}");
    assert!((a - b).norm() < 0.02 * a.norm(), "{a:?} {b:?}");
}

#[test]
fn five_axis_input_faults_are_typed() {
    let (job, seed) = kr300_job(1.0e-3);
    let program = read(SWARF);
    let bad = Options {
        depth: 0.0,
        ..Options::default()
    };
    let e = five_axis::run(&job, &program, &seed, &bad).unwrap_err();
    assert!(e.to_string().contains("depth"), "{e}");
    let e = five_axis::run(&job, &program, &seed[..5], &Options::default()).unwrap_err();
    assert!(e.to_string().contains("seed"), "{e}");
    // The z-map job refuses the tilted program rather than drop its axis.
    let e = job::run(&job, &program, &seed).unwrap_err();
    assert!(e.to_string().contains("2.5-D"), "{e}");
    // A counter-clockwise spindle is refused where it cuts, naming the line.
    let ccw = read(&SWARF.replace("CLW", "CCLW"));
    let e = five_axis::run(&job, &ccw, &seed, &Options::default()).unwrap_err();
    assert!(matches!(e, JobError::AtLine { line: 9, .. }), "{e}");
}

#[test]
fn the_part_mesh_writes_as_ply_ascii_and_binary() {
    use deflect_core::io::ply::{self, Format};
    use deflect_core::machining::dexel::surface::SurfacePoint;
    let p = |x: f64, y: f64, dev: f64| SurfacePoint {
        position: Vector3::new(x, y, -0.001),
        normal: Vector3::z(),
        deviation: dev,
        ray: (2, (x * 1e3) as usize, (y * 1e3) as usize),
        upper: true,
    };
    // Four points of a square floor, 1 mm apart: two triangles.
    let points = vec![
        p(0.0, 0.0, 1e-5),
        p(0.001, 0.0, -2e-5),
        p(0.0, 0.001, 0.0),
        p(0.001, 0.001, 3e-6),
    ];
    let mesh = SurfaceMesh::new(points, 1e-3).unwrap();
    assert_eq!(mesh.triangles.len(), 2);
    let mut ascii = Vec::new();
    ply::write(&mesh, Format::Ascii, &mut ascii).unwrap();
    let text = String::from_utf8(ascii).unwrap();
    let (header, body) = text.split_once("end_header\n").unwrap();
    assert!(header.contains("element vertex 4\n") && header.contains("element face 2\n"));
    let rows: Vec<Vec<f32>> = body
        .lines()
        .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 6);
    assert_eq!(
        rows[1][..],
        [0.001, 0.0, -0.001, 0.0, 0.0, 1.0, -2e-5, 4.0][..]
    );
    assert_eq!(rows[4][0], 3.0);
    let mut binary = Vec::new();
    ply::write(&mesh, Format::Binary, &mut binary).unwrap();
    let at = binary
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    assert_eq!(binary.len() - at, 4 * 29 + 2 * 13);
    let x1 = f32::from_le_bytes(binary[at + 29..at + 33].try_into().unwrap());
    assert_eq!(x1, 0.001f32);
}

#[test]
fn the_spin_turns_the_tool_about_the_programs_axis_and_the_search_lowers_the_deflection() {
    use deflect_core::machining::spin::{self, LoadPath, SpinOptions, SpinSchedule};
    let (job, seed) = kr300_job(1.0e-3);
    let program = read(SWARF);
    let options = Options::default();
    let plain = five_axis::run(&job, &program, &seed, &options).unwrap();
    // A constant 30 degrees: the rigid TCP's z stays on the program's axis (reversed) and
    // its x turns by 30 degrees about it.
    let turned = job
        .clone()
        .with_spin(SpinSchedule::constant(30f64.to_radians()).unwrap());
    let r = five_axis::run(&turned, &program, &seed, &options).unwrap();
    let robot = fixtures::kr300();
    let mut data = Data::new(&robot.model);
    let rot = job.setup().placement.rotation;
    let k = r.samples.iter().position(|s| s.bands > 0).unwrap() + 40;
    let (a, b) = (&plain.samples[k], &r.samples[k]);
    assert_eq!(b.spin, 30f64.to_radians());
    let mut frame = |q: &[f64; 8]| {
        let t = vjm::forward(&robot.model, &mut data, &q[..6]).unwrap();
        rot.inverse() * t.rotation
    };
    let (fa, fb) = (frame(&a.q), frame(&b.q));
    assert!((fb * Vector3::z() + b.path.axis).norm() < 1e-8);
    let (xa, xb) = (fa * Vector3::x(), fb * Vector3::x());
    let angle = xa.cross(&xb).dot(&(fa * Vector3::z())).atan2(xa.dot(&xb));
    assert!(
        (angle.abs() - 30f64.to_radians()).abs() < 1e-7,
        "{}",
        angle.to_degrees()
    );
    // The compensated tool still holds the program.
    assert!(r.errors(true).max_position <= job.setup().ik.position_tolerance);
    // The search over the five-axis loads: no worse than the seed's spin, and the run with
    // its schedule follows it.
    let o = SpinOptions::default();
    let loads =
        LoadPath::new_five_axis(&job, &program, &options, o.step, o.per_metre, o.per_second)
            .unwrap();
    let plan = spin::plan(&job, &loads, &seed, &o).unwrap();
    let seed_cost = plan.seed.unwrap();
    assert!(
        plan.optimised.rms <= seed_cost.rms * (1.0 + 1e-12),
        "{plan:?}"
    );
    let searched = job.clone().with_spin(plan.schedule.clone());
    let r = five_axis::run(&searched, &program, &seed, &options).unwrap();
    assert!(r.errors(true).max_position <= job.setup().ik.position_tolerance);
    // The load path's bytes carry the stations' axes.
    let back = LoadPath::from_bytes(&loads.to_bytes()).unwrap();
    assert_eq!(back, loads);
}
