//! The offline pass over a program against hand-derived values: the path's duration is the
//! closed-form profile's, it stops at corners and runs through tangent joins; the engagement
//! of a slot is 0..pi at the programmed depth and half immersion is a quarter turn; the force
//! of a slot on the KR 300 equals Altintas' closed form for slotting; the compensated arm
//! lands on the program and the uncompensated one leaves material; every fault names its
//! program line.

mod fixtures;

use std::f64::consts::PI;

use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::machining::cutting::Coefficients;
use deflect_core::machining::engagement::{self, Contact};
use deflect_core::machining::job;
use deflect_core::machining::path::{self, PathOptions};
use deflect_core::machining::stock::{Cutter, ZMap};
use deflect_core::motion::{Limits, Profile};
use deflect_core::units::LengthUnit;
use deflect_core::{JobError, TickError};
use nalgebra::{Vector2, Vector3};

use fixtures::mm_program as program;

#[test]
fn a_line_takes_the_closed_form_profile_time_and_ends_exactly() {
    let p = program("G1 X60 F1500\n");
    let o = PathOptions::default();
    let profile = Profile::new(0.06, &Limits::new(0.025, o.acceleration, o.jerk).unwrap()).unwrap();
    let t = path::duration(&p, &o).unwrap();
    assert_eq!(t, profile.duration());
    let s = path::sample(&p, &o).unwrap();
    assert_eq!(s.len(), (t * 250.0 - 1e-9).ceil() as usize + 1);
    assert_eq!(s[0].position, Vector3::new(0.0, 0.0, 0.02));
    let last = s.last().unwrap();
    assert_eq!(last.position, Vector3::new(0.06, 0.0, 0.02));
    assert_eq!(last.time, t);
    assert!(s.iter().all(|x| x.speed <= 0.025 + 1e-15 && x.line == 1));
    // Samples 4 ms apart.
    assert!((s[10].time - 0.04).abs() < 1e-15);
}

#[test]
fn the_tool_stops_at_a_corner_and_runs_through_a_tangent_join() {
    let o = PathOptions::default();
    // Corner: two perpendicular lines take the two profiles' time, speed 0 at the corner.
    let corner = program("G0 X0 Y0 Z0\nG1 X10 F600\nY10\n");
    let lim = Limits::new(0.01, o.acceleration, o.jerk).unwrap();
    let one = Profile::new(0.01, &lim).unwrap().duration();
    let rapid = Profile::new(0.02, &Limits::new(0.25, 2.0, 20.0).unwrap()).unwrap();
    let t = path::duration(&corner, &o).unwrap();
    assert!((t - (rapid.duration() + 2.0 * one)).abs() < 1e-12);
    // Tangent: a line into a quarter circle that starts along it is one run at the feed.
    let tangent = program("G0 X0 Y0 Z0\nG1 X10 F600\nG3 X20 Y10 R10\n");
    let length = 0.01 + 0.01 * PI / 2.0;
    let t = path::duration(&tangent, &o).unwrap();
    let run = Profile::new(length, &lim).unwrap().duration();
    assert!((t - (rapid.duration() + run)).abs() < 1e-12);
    let s = path::sample(&tangent, &o).unwrap();
    let join = s.iter().find(|x| x.line == 3).expect("samples on the arc");
    assert!((join.speed - 0.01).abs() < 1e-12, "{}", join.speed);
    // A full circle (G2 with I) returns to its start.
    let circle = program("G0 X10 Y0 Z0\nG2 X10 Y0 I5 F600\n");
    let s = path::sample(&circle, &o).unwrap();
    let end = s.last().unwrap().position;
    assert!((end - Vector3::new(0.01, 0.0, 0.0)).norm() < 1e-9);
    // Midway round the circle the tool is opposite the start.
    let mid = path::duration(&circle, &o).unwrap()
        - Profile::new(0.01 * PI, &lim).unwrap().duration() / 2.0;
    let m = s
        .iter()
        .min_by(|a, b| (a.time - mid).abs().total_cmp(&(b.time - mid).abs()))
        .unwrap();
    assert!((m.position - Vector3::new(0.02, 0.0, 0.0)).norm() < 1e-4);
}

#[test]
fn path_budgets_and_faults_are_typed() {
    let p = program("G1 X60 F1500\n");
    let o = PathOptions {
        rate_hz: 0.0,
        ..PathOptions::default()
    };
    assert!(path::sample(&p, &o).is_err());
    // 10 m at 1 mm/min: 6e5 s (within MAX_DURATION), far past MAX_PATH_SAMPLES.
    let long = program("G1 X10000 F1\n");
    let e = path::sample(&long, &PathOptions::default()).unwrap_err();
    assert!(e.to_string().contains("MAX_PATH_SAMPLES"), "{e}");
    // 900 m at 1 mm/min: 5.4e7 s, a move no controller runs.
    let endless = program("G1 X900000 F1\n");
    let e = path::sample(&endless, &PathOptions::default()).unwrap_err();
    assert!(e.to_string().contains("MAX_DURATION"), "{e}");
    let still = program("G0 X0 Y0 Z20\n");
    assert!(path::sample(&still, &PathOptions::default()).is_err());
}

#[test]
fn a_slot_engages_zero_to_pi_at_its_depth_and_half_immersion_a_quarter() {
    let cell = 2.0e-4;
    let r = 0.008;
    let mut z = ZMap::new(Vector2::new(0.0, -0.03), Vector2::new(0.1, 0.03), 0.0, cell).unwrap();
    let flat = Cutter::Flat { radius: r };
    let a = 0.002;
    let _ = z
        .cut(
            &flat,
            &Vector3::new(0.0, 0.0, -a),
            &Vector3::new(0.05, 0.0, -a),
        )
        .unwrap();
    let c = engagement::contact(&z, r, &Vector3::new(0.05, 0.0, -a), &Vector3::x());
    let Some(engagement::Arc { entry, exit, depth }) = c.span() else {
        panic!("{c:?}")
    };
    assert_eq!(c.arcs().len(), 1);
    assert_eq!((entry, exit), (0.0, PI));
    assert!((depth - a).abs() < 1e-12);
    // A second pass beside the slot, offset by R to +y: the material left lies on the tool's
    // +y side (left of the feed, phi in [0, pi/2]): up milling at half immersion.
    let mut z2 = z.clone();
    let _ = z2
        .cut(&flat, &Vector3::new(0.0, r, -a), &Vector3::new(0.03, r, -a))
        .unwrap();
    let c = engagement::contact(&z2, r, &Vector3::new(0.03, r, -a), &Vector3::x());
    let Some(engagement::Arc {
        entry: entry2,
        exit: exit2,
        depth: depth2,
    }) = c.span()
    else {
        panic!("{c:?}")
    };
    // The probe of angle phi reads the rim's lateral offset R cos(phi) ahead of the tool:
    // the first slot's wall lies at lateral R from this pass, i.e. at phi = pi/2, where the
    // interpolation between the cut row (centre 0.1 mm inside) and the uncut one reads half
    // the depth. So the arc ends at pi/2 and its mean depth is (90 a + a/2) / 91.
    assert_eq!(entry2, 0.0);
    assert!((exit2 - PI / 2.0).abs() < 1e-12, "{exit2}");
    assert!((depth2 - a * 90.5 / 91.0).abs() < 1e-12, "{depth2}");
    // Back along the groove already cut: only the walls beside the rim are seen, as two thin
    // arcs at the ends where R cos(phi) passes the last cut row's centre (R - cell/2), no
    // wider than acos(1 - cell / R) + one probe step each.
    let c = engagement::contact(&z, r, &Vector3::new(0.02, 0.0, -a), &Vector3::x());
    let sliver = (1.0 - cell / r).acos() + PI / 180.0;
    assert_eq!(c.arcs().len(), 2, "{c:?}");
    assert_eq!(c.arcs()[0].entry, 0.0);
    assert!(c.arcs()[0].exit <= sliver && c.arcs()[1].entry >= PI - sliver);
    // Above the stock: air. Straight down into the stock: a plunge.
    let c = engagement::contact(&z, r, &Vector3::new(0.02, 0.0, 0.001), &Vector3::x());
    assert_eq!(c, Contact::Air);
    let c = engagement::contact(&z, r, &Vector3::new(0.08, 0.0, -a), &-Vector3::z());
    assert!(matches!(c, Contact::Plunge { depth } if (depth - a).abs() < 1e-12));
}

use fixtures::kr300_job;

/// The slotting average of the 16 mm three-flute mill in Al7075 at depth `a` and feed per
/// tooth `c`, tool frame: Altintas' closed forms (2.14-2.16 of Manufacturing Automation).
fn slot_force(a: f64, c: f64) -> Vector3<f64> {
    let k = Coefficients::AL7075_T6_CARBIDE;
    let n = 3.0;
    Vector3::new(
        -n * a * k.k_rc * c / 4.0 - n * a * k.k_re / PI,
        n * a * k.k_tc * c / 4.0 + n * a * k.k_te / PI,
        n * a * k.k_ac * c / PI + n * a * k.k_ae / 2.0,
    )
}

const SLOT: &str = "G0 X-10 Y0 Z5\nS13000 M3\nG1 Z-2 F1500\nX70\nG0 Z5\n";

#[test]
fn a_slot_on_the_kr300_has_the_closed_form_force_and_is_compensated() {
    let (job, q0) = kr300_job();
    let p = program(SLOT);
    let r = job::run(&job, &p, &q0).unwrap();
    // Mid-slot, at the feed: Altintas' slotting averages (2.14-2.16 of Manufacturing
    // Automation), N = 3, a = 2 mm, c = 25 mm/s / (13000/60 rev/s x 3).
    let c = 0.025 / (13000.0 / 60.0 * 3.0);
    let expected = slot_force(0.002, c);
    let mid = r
        .samples
        .iter()
        .find(|s| s.path.line == 4 && s.path.position.x > 0.035)
        .unwrap();
    assert!((mid.feed_per_tooth - c).abs() < 1e-12 * c);
    assert!(
        (mid.force - expected).norm() < 1e-9 * expected.norm(),
        "{} vs {expected}",
        mid.force
    );
    // The tip deflects by tenths of a mm; the compensated tip lands within the IK tolerance,
    // the uncompensated one is off by the deflection.
    let d = mid.deflection.fixed_rows::<3>(0).norm();
    assert!(d > 2e-5, "{d}");
    let un = r.path_error(false);
    let co = r.path_error(true);
    assert!(un.max > 2e-5 && co.max < 1e-7, "{un:?} {co:?}");
    // The uncompensated slot is shallower: material left on the floor (tool pushed up by
    // the axial force), the compensated one cut as programmed to a micrometre.
    let s_un = r.surface_error(&r.uncompensated);
    let s_co = r.surface_error(&r.compensated);
    assert!(
        s_un.floor.max > 1e-5 && s_co.floor.max < 1e-6,
        "{s_un:?} {s_co:?}"
    );
    // Pushed sideways, the uncompensated groove leaves a strip of one wall and cuts into the
    // other: tens of micrometres along its 80 mm, square millimetres; the compensated one
    // matches it to tens of square micrometres: its tool within the IK's 1e-8 m of the
    // program, a wall 1e-8 m off along 80 mm would be 800 um^2.
    assert!(s_un.material_left > 1e-6 && s_un.overcut > 1e-6, "{s_un:?}");
    assert!(
        s_co.material_left < 5e-11 && s_co.overcut < 1e-9,
        "{s_co:?}"
    );
    // The nominal groove: depth 2 mm at its middle.
    let (i, j) = ((0.04 / 5e-4) as usize, (0.03 / 5e-4) as usize);
    assert!((r.nominal.height(i, j).unwrap() + 0.002).abs() < 1e-12);
    // The pilot signal is the wrench 40 ms (10 samples) early.
    let pilot = r.pilot_wrenches(0.04);
    assert_eq!(pilot[0], r.samples[10].wrench);
    assert_eq!(*pilot.last().unwrap(), r.samples.last().unwrap().wrench);
    let lines = r.line_forces();
    let slot = lines.iter().find(|l| l.line == 4).unwrap();
    assert!(slot.max >= expected.norm() * (1.0 - 1e-9));
}

/// A slot fed at 30 degrees feels the +x slot's closed form turned by 30 degrees about z
/// (the workpiece frame's force), and one along an arc of 100 mm radius the same closed form
/// along its tangent at the arc's top, within the 8 mm tool's curvature effect (the chip of a
/// curved groove is not a straight one's: 8 / 100 of the width, bounded here by 3 %).
#[test]
fn diagonal_and_arc_slots_feel_the_closed_form_along_their_feed() {
    let (job, q0) = kr300_job();
    let c = 0.025 / (13000.0 / 60.0 * 3.0);
    let slot = slot_force(0.002, c);
    // 70 tan(30 deg) = 40.4145 mm.
    let diagonal = "G0 X-10 Y-20 Z5\nS13000 M3\nG1 Z-2 F1500\nX60 Y20.41452\nG0 Z5\n";
    let r = job::run(&job, &program(diagonal), &q0).unwrap();
    let mid = r
        .samples
        .iter()
        .find(|s| s.path.line == 4 && s.path.position.x > 0.03)
        .unwrap();
    let turn = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), PI / 6.0);
    let want = turn * slot;
    assert!(
        (mid.force - want).norm() < 1e-6 * want.norm(),
        "{} vs {want}",
        mid.force
    );
    // Clockwise over the top of a 100 mm arc from (-10, -25) to (70, -25) mm: its top at
    // x = 30 mm, feed along +x there.
    let arc = "G0 X-10 Y-25 Z5\nS13000 M3\nG1 Z-2 F1500\nG2 X70 Y-25 R100\nG0 Z5\n";
    let r = job::run(&job, &program(arc), &q0).unwrap();
    let top = r
        .samples
        .iter()
        .filter(|s| s.path.line == 4)
        .min_by(|p, q| {
            (p.path.position.x - 0.03)
                .abs()
                .total_cmp(&(q.path.position.x - 0.03).abs())
        })
        .unwrap();
    assert!(top.path.direction.x > 0.9999, "{:?}", top.path.direction);
    assert!(
        (top.force - slot).norm() < 0.03 * slot.norm(),
        "{} vs {slot}",
        top.force
    );
    // The arc turns the force: its x and y parts keep their signs, not mirrored.
    assert!(top.force.x.signum() == slot.x.signum() && top.force.y.signum() == slot.y.signum());
}

/// A ramp into the stock: at each sample the probes ahead read the uncut top, so the chip is
/// a slot as deep as the tip is below the top there, and the force that slot's closed form
/// at the sample's own depth and feed per tooth (the path speed's horizontal part: 25 mm/s
/// along a ramp of 3 mm over 80 mm is 25 x 80 / sqrt(80^2 + 3^2) mm/s across the stock).
#[test]
fn a_ramp_feels_the_slot_of_its_current_depth() {
    let (job, q0) = kr300_job();
    let ramp = "G0 X-10 Y0 Z5\nS13000 M3\nG1 Z0 F1500\nX70 Z-3\nG0 Z5\n";
    let r = job::run(&job, &program(ramp), &q0).unwrap();
    let c = 0.025 * 80.0 / 6409f64.sqrt() / (13000.0 / 60.0 * 3.0);
    let mut checked = 0;
    for s in r
        .samples
        .iter()
        .filter(|s| s.path.line == 4 && (0.02..0.06).contains(&s.path.position.x))
    {
        // At full feed between the ramp's ends (the jerk-limited start and stop elsewhere).
        if (s.feed_per_tooth - c).abs() > 1e-12 * c {
            continue;
        }
        let slot = slot_force(-s.path.position.z, c);
        assert!(
            (s.force - slot).norm() < 1e-9 * slot.norm(),
            "x = {}: {} vs {slot}",
            s.path.position.x,
            s.force
        );
        checked += 1;
    }
    assert!(checked > 50, "{checked}");
}

#[test]
fn faults_name_their_program_line() {
    let (job, q0) = kr300_job();
    // The spindle never started.
    let e = job::run(&job, &program("G0 X-10 Y0 Z5\nG1 Z-2 F1500\nX70\n"), &q0).unwrap_err();
    assert!(matches!(e, JobError::SpindleOff { line: 3, .. }), "{e}");
    assert!(e.to_string().starts_with("program line 3"), "{e}");
    // A rapid through the stock.
    let e = job::run(&job, &program("G0 X-10 Y0 Z-1\nS13000 M3\nG0 X70\n"), &q0).unwrap_err();
    assert!(matches!(e, JobError::RapidInStock { line: 3, .. }), "{e}");
    // Five metres away: out of reach at the line that goes there.
    let e = job::run(&job, &program("S13000 M3\nG0 Z5\nG0 X5000\n"), &q0).unwrap_err();
    assert!(
        matches!(
            e,
            JobError::AtLine {
                line: 3,
                error: TickError::NotConverged { .. }
                    | TickError::Singular { .. }
                    | TickError::JointLimit { .. },
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("program line 3"), "{e}");
    // A seed of the wrong length.
    assert!(matches!(
        job::run(&job, &program(SLOT), &q0[..5]),
        Err(JobError::Setup(_))
    ));
}

#[test]
fn the_compensated_gcode_reads_back_onto_the_commanded_path() {
    let (job, q0) = kr300_job();
    let p = program(SLOT);
    let r = job::run(&job, &p, &q0).unwrap();
    let text = deflect_core::io::job_out::compensated_gcode(&r, &p, 1e-6);
    let back = gcode::from_str(
        &text,
        &GcodeOptions {
            start: r.samples[0].commanded.translation.vector,
            units: LengthUnit::Millimetre,
            ..GcodeOptions::default()
        },
    )
    .unwrap();
    // Far fewer blocks than samples, every commanded point within the tolerance (plus the
    // 0.05 um of four decimals in mm) of the polyline read back.
    assert!(
        back.moves.len() < r.samples.len() / 10,
        "{}",
        back.moves.len()
    );
    let poly: Vec<Vector3<f64>> = back.moves.iter().map(|m| m.end).collect();
    for s in &r.samples {
        let c = s.commanded.translation.vector;
        let d = poly
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                let t = ((c - a).dot(&(b - a)) / (b - a).norm_squared().max(1e-30)).clamp(0.0, 1.0);
                (c - (a + (b - a) * t)).norm()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1.0e-6 + 1.0e-7, "{d} at t = {}", s.path.time);
    }
    // The slot's floor is commanded below the programmed -2 mm (the arm is pushed up).
    let deepest = poly.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    assert!(deepest < -0.002 - 1e-5, "{deepest}");
    // The feeds are the program's, in mm/min.
    assert!(text.contains("F1500.0"), "{text}");
    let csv = deflect_core::io::job_out::samples_csv(&r, 0.04);
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 12 + 12 + 3 + 3 + 6 + 3);
    assert_eq!(lines.count(), r.samples.len());
}

#[test]
fn a_points_csv_is_a_program_of_straight_moves_in_its_units() {
    use deflect_core::io::points_csv;
    use deflect_core::machining::Motion;
    let o = GcodeOptions {
        start: Vector3::zeros(),
        units: LengthUnit::Millimetre,
        ..GcodeOptions::default()
    };
    let p = points_csv::from_str(
        "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n0,0,5,0,0\n10,0,-2,1500,13000\n",
        &o,
    )
    .unwrap();
    assert_eq!(p.moves.len(), 2);
    assert_eq!(p.moves[0].motion, Motion::Rapid);
    assert_eq!(p.moves[1].motion, Motion::Linear);
    assert_eq!(p.moves[1].end, Vector3::new(0.01, 0.0, -0.002));
    assert!((p.moves[1].feed - 0.025).abs() < 1e-15);
    assert!((p.moves[1].spindle - 13000.0 / 60.0).abs() < 1e-12);
    assert_eq!((p.moves[0].line, p.moves[1].line), (2, 3));
    let m =
        points_csv::from_str("x_m,y_m,z_m,feed_m_s,spindle_rpm\n0.01,0,0,0.025,100\n", &o).unwrap();
    assert_eq!(m.moves[0].end.x, 0.01);
    // Faults: a missing spindle, an orientation column, a NaN, both units, out of range.
    for (text, needle) in [
        ("x_mm,y_mm,z_mm,feed_mm_min\n0,0,0,1\n", "spindle_rpm"),
        (
            "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm,qw\n0,0,0,1,1,1\n",
            "qw",
        ),
        (
            "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n0,nan,0,1,1\n",
            "y_mm",
        ),
        (
            "x_mm,x_m,y_mm,z_mm,feed_mm_min,spindle_rpm\n0,0,0,0,1,1\n",
            "x_m",
        ),
        (
            "x_mm,y_mm,z_mm,feed_mm_min,spindle_rpm\n0,0,0,-5,1\n",
            "feed_mm_min",
        ),
    ] {
        let e = points_csv::from_str(text, &o).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
    }
}

#[test]
fn a_hand_built_program_is_checked_like_a_read_one() {
    use deflect_core::machining::{Motion, Move, Plane, Program};
    let line = |start: Vector3<f64>, end: Vector3<f64>| Move {
        spindle: 100.0,
        ..Move::new(1, Motion::Linear, start, end, 0.01)
    };
    let (a, b, c) = (
        Vector3::zeros(),
        Vector3::new(0.01, 0.0, 0.0),
        Vector3::new(0.01, 0.01, 0.0),
    );
    let ok = Program {
        moves: vec![line(a, b), line(b, c)],
        ..Program::default()
    };
    ok.validate().unwrap();
    let text = |p: &Program| p.validate().unwrap_err().to_string();
    // A gap between moves, a negative feed, a NaN point, an arc that does not end where its
    // sweep takes it: each names the move.
    let mut gap = ok.clone();
    gap.moves[1].start.x += 1e-6;
    assert!(
        text(&gap).contains("MAX_GAP") && text(&gap).contains("1"),
        "{}",
        text(&gap)
    );
    let mut feed = ok.clone();
    feed.moves[0].feed = -1.0;
    assert!(text(&feed).contains("feed"), "{}", text(&feed));
    let mut nan = ok.clone();
    nan.moves[1].end.y = f64::NAN;
    assert!(text(&nan).contains("finite"), "{}", text(&nan));
    let mut arc = ok.clone();
    arc.moves[1].motion = Motion::Arc {
        plane: Plane::Xy,
        center: Vector3::new(0.01, 0.005, 0.0),
        sweep: PI / 2.0,
    };
    assert!(text(&arc).contains("ARC_TOLERANCE"), "{}", text(&arc));
    // A half turn about the chord's midpoint is consistent.
    arc.moves[1].motion = Motion::Arc {
        plane: Plane::Xy,
        center: Vector3::new(0.01, 0.005, 0.0),
        sweep: PI,
    };
    arc.validate().unwrap();
    // The path refuses what validate refuses.
    assert!(path::sample(&gap, &PathOptions::default()).is_err());
}
