//! The compensated prediction stays on the program: on the sloped zig-zag that left it by
//! 0.66 mm (`../shared/machining/sloped_floor_zigzag.nc`), on zig-zags of other slopes and
//! stepovers, on a ramp, on a ball-end bowl and on a wavy 3-D raster, the compensated tip is
//! within `PREDICTION_TOLERANCE` (1 um) of the program at every feed sample, with no line
//! named as deviating; the uncompensated tip is not (the tests would notice a compensation
//! that did nothing).

use deflect_core::machining::Program;
use deflect_core::machining::cutting::Tool;
use deflect_core::machining::job::{self, Job, PREDICTION_TOLERANCE};
use deflect_core::machining::tools::{ToolShape, ToolSpec, ToolTable};
use deflect_tests::{JOB_SEED, job_setup, kr300, programs, read_mm as read};
use nalgebra::Vector2;

/// `deflect-sim job`'s defaults: the KR 300, its placement, the stock the feed moves' box
/// grown by the tool radius, 0.5 mm cells, a 16 mm three-flute end mill in Al7075.
fn job(program: &Program, tools: Option<ToolTable>) -> Job {
    let radius = 0.008;
    let (mut lo, mut hi) = (
        Vector2::repeat(f64::INFINITY),
        Vector2::repeat(f64::NEG_INFINITY),
    );
    for m in program.moves.iter().filter(|m| m.is_feed()) {
        for p in [m.start.xy(), m.end.xy()] {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    }
    let setup = job_setup(
        lo - Vector2::repeat(radius),
        hi + Vector2::repeat(radius),
        5.0e-4,
    );
    let robot = kr300();
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup).unwrap();
    match tools {
        Some(t) => job.with_tools(t),
        None => job,
    }
}

/// Runs `text` and checks the compensated prediction against the tolerance; returns the
/// (uncompensated, compensated) largest path errors [m].
fn check(name: &str, text: &str, tools: Option<ToolTable>) -> (f64, f64) {
    let program = read(text);
    let job = job(&program, tools);
    let r = job::run(&job, &program, &JOB_SEED).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (u, c) = (r.path_error(false).max, r.path_error(true).max);
    let off: Vec<_> = r
        .line_forces()
        .into_iter()
        .filter(|l| l.deviation.is_some())
        .collect();
    assert!(
        c <= PREDICTION_TOLERANCE && off.is_empty() && r.summary.deviating_samples() == 0,
        "{name}: compensated path error {c:e} m, lines off {off:?}"
    );
    assert!(
        u > 20.0 * PREDICTION_TOLERANCE,
        "{name}: uncompensated {u:e} m"
    );
    (u, c)
}

#[test]
fn the_sloped_zigzag_that_left_the_program_stays_on_it() {
    let path = deflect_tests::shared_path("machining/sloped_floor_zigzag.nc");
    let Ok(text) = std::fs::read_to_string(&path) else {
        eprintln!("{path} not found: the reproducer is skipped (DEFLECT_SHARED names the folder)");
        return;
    };
    let (u, c) = check("sloped_floor_zigzag.nc", &text, None);
    // The arm's deflection is real (more than a millimetre uncompensated) ...
    assert!(u > 1.0e-3, "{u}");
    // ... and the compensated tool is back on the program to the IK's tolerance.
    assert!(c < 5.0e-8, "{c}");
}

#[test]
fn zigzags_of_any_slope_and_stepover_stay_on_the_program() {
    // Slopes of 0.1 to 5 % along the feed, stepovers of 0.1 to 4 mm (a finishing pass to a
    // roughing one): 20 variants of the reproducer, shorter.
    for slope in [0.001, 0.005, 0.01, 0.02, 0.05] {
        for stepover in [0.1, 0.3, 1.0, 4.0] {
            let text = programs::sloped_zigzag(6, 8.0, stepover, 3.0, slope);
            check(
                &format!("slope {slope}, stepover {stepover} mm"),
                &text,
                None,
            );
        }
    }
}

#[test]
fn a_ramp_and_a_small_stepover_raster_stay_on_the_program() {
    // A ramp down 2 mm over 12 mm then back up, then a raster of a floor tilted both ways.
    let ramp = "G21 G90 G17\nS8000 M3\nG0 X0 Y0 Z2\nG1 Z-1 F900\nX12 Z-3\nX24 Z-1\nG0 Z5\nM2\n";
    check("ramp", ramp, None);
    let tilted = programs::raster(
        |x, y| -2.0 - 0.02 * x - 0.01 * y,
        (0.0, 10.0),
        (0.0, 1.0),
        0.25,
        2.0,
        900.0,
        8000.0,
    );
    check("tilted raster, 0.25 mm stepover", &tilted, None);
}

#[test]
fn three_d_floors_with_a_ball_end_mill_stay_on_the_program() {
    let ball = ToolTable::new(vec![ToolSpec {
        number: 1,
        tool: Tool::new(0.010, 2, 0.5).unwrap(),
        shape: ToolShape::Ball,
        length: 0.1,
        name: "10 mm ball".into(),
    }])
    .unwrap();
    let bowl = programs::raster(
        programs::bowl(8.0, 2.0),
        (-8.0, 8.0),
        (-3.0, 3.0),
        0.5,
        1.0,
        1200.0,
        12000.0,
    );
    check("ball-end bowl", &bowl, Some(ball.clone()));
    let waves = programs::raster(
        programs::waves(2.0, 1.0),
        (0.0, 12.0),
        (0.0, 2.0),
        0.3,
        0.5,
        1200.0,
        12000.0,
    );
    check("wavy 3-D raster", &waves, Some(ball));
}
