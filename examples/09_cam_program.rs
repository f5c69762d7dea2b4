//! Example 9: a CAM program with two tools on the KR 300. A program as a CAM post writes it
//! for a mill (tool changes, tool length offsets, coolant, a work offset, a drilling cycle, a
//! pocket by a parametric loop) is read as LinuxCNC reads it; its word report says what the
//! reader does with each word; a LinuxCNC tool table maps its `T1` and `T2` to a 10 mm and a
//! 6 mm flat end mill (their lengths recorded: the TCP carries them), and the offline pass cuts
//! each move with the tool in the spindle.
//! Prints the word report, the tools and the force and path error per tool.
//!
//! Run: `cargo run --release --example 09_cam_program`

use deflect_core::SerialRobot;
use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::io::tool_table::{self, TblOptions};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::mechanism::PoseIkOptions;
use nalgebra::{Isometry3, Vector2, Vector3};

/// The program: a slot with T1, two drilled holes and a circular pocket (a while loop of
/// helical passes) with T2.
const PROGRAM: &str = "%
(two tools, as a post writes them)
G21 G90 G17 G94 G40 G49 G80
G54
T1 M6
G43 H1
S12000 M3 M8
G0 X-10 Y10 Z5
G1 Z-2 F600
X70 F1500
G0 Z5
T2 M6
G43 H2
S15000 M3
G98 G81 X20 Y35 Z-3 R2 F300
X50
G80
G0 X40 Y35 Z2
#<depth> = 0
o1 while [#<depth> LT 1.5]
  #<depth> = [#<depth> + 0.5]
  G1 X46 Y35 F900
  G3 X46 Y35 I-6 J0 Z[0 - #<depth>]
o1 endwhile
G0 Z5
M5 M9
M30
%
";

/// The tool table, LinuxCNC's form (mm).
const TOOLS: &str = "T1 P1 D10 Z52.3 ;10 mm flat end mill\nT2 P2 D6 Z61.0 ;6 mm end mill\n";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = env!("CARGO_MANIFEST_DIR");
    let options = GcodeOptions {
        start: Vector3::new(0.0, 0.0, 0.02),
        ..GcodeOptions::default()
    };
    println!(
        "{:<12} {:<9} {:>5} {:>5}  meaning",
        "word", "status", "count", "line"
    );
    for w in gcode::words(PROGRAM, &options)? {
        println!(
            "{:<12} {:<9} {:>5} {:>5}  {}",
            w.word,
            w.status.name(),
            w.count,
            w.first_line,
            w.meaning
        );
    }
    let program = gcode::from_str(PROGRAM, &options)?;
    let tools = tool_table::tbl_from_str(
        TOOLS,
        &TblOptions {
            flutes: 2,
            ..TblOptions::default()
        },
    )?;
    println!("{} moves; tools {:?}", program.moves.len(), program.tools());
    let robot = SerialRobot::from_path(
        format!("{root}/robots/kr300/kr300_r2500.urdf"),
        format!("{root}/robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )?;
    let setup = Setup {
        placement: Isometry3::new(
            Vector3::new(2.45, 0.02, 0.92),
            Vector3::new(0.0, 0.0, std::f64::consts::PI),
        ),
        tool_orientation: Setup::tool_down(),
        // Serves only a T the table lacks; the table has both.
        tool: Tool::new(0.016, 3, 0.0)?,
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min: Vector2::new(-0.005, 0.0),
            max: Vector2::new(0.075, 0.05),
            top: 0.0,
            cell: 5.0e-4,
        },
        path: PathOptions::default(),
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: job::RAPID_SKIM,
    };
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup)?.with_tools(tools);
    let report = job::run(&job, &program, &[0.0, -0.9, 1.4, 0.0, -0.5, 0.0])?;
    for t in program.tools() {
        let (force, error) = report
            .samples
            .iter()
            .filter(|s| s.path.tool == t && s.path.feed_move)
            .fold((0.0f64, 0.0f64), |(f, e), s| {
                (
                    f.max(s.force.norm()),
                    e.max((s.actual_uncompensated - s.path.position).norm()),
                )
            });
        let spec = job.tools().and_then(|table| table.get(t));
        println!(
            "T{t} ({}): largest force {force:.1} N, path error uncompensated {:.3} mm",
            spec.map_or("?", |s| s.name.as_str()),
            error * 1e3
        );
    }
    let (u, c) = (report.path_error(false), report.path_error(true));
    println!(
        "path error max: uncompensated {:.3} mm, compensated {:.6} mm",
        u.max * 1e3,
        c.max * 1e3
    );
    Ok(())
}
