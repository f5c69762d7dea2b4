//! Example 10: the built-in job on the KR 300, from the program to the robot's own program:
//! the spin about the tool axis chosen along the program for the least deflection, the KRL of
//! both commands (`LIN` of `E6POS` with status and turn, `PTP` of `E6AXIS`), and the placement
//! of the workpiece searched in a box around the job's own.
//! Prints the spin search's figures, the first motions of the KRL and the best placement.
//!
//! Run: `cargo run --release --example 10_robot_program`

use deflect_core::SerialRobot;
use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::io::robot_program::{self, Command, Language, ProgramOptions, Target};
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::placement::{self, PlacementBox, Problem};
use deflect_core::machining::spin::{self, LoadPath, SpinOptions};
use deflect_core::mechanism::PoseIkOptions;
use nalgebra::{Isometry3, Vector2, Vector3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/");
    let robot = SerialRobot::from_path(
        format!("{dir}robots/kr300/kr300_r2500.urdf"),
        format!("{dir}robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )?;
    let text = std::fs::read_to_string(format!("{dir}data/groove_and_pocket.nc"))?;
    let options = GcodeOptions {
        start: Vector3::new(0.0, 0.0, 0.02),
        units: deflect_core::units::LengthUnit::Millimetre,
        ..GcodeOptions::default()
    };
    let program = gcode::from_str(&text, &options)?;
    let setup = Setup {
        placement: Isometry3::new(
            Vector3::new(2.45, 0.02, 0.92),
            Vector3::new(0.0, 0.0, std::f64::consts::PI),
        ),
        tool_orientation: Setup::tool_down(),
        tool: Tool::new(0.016, 3, 0.0)?,
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min: Vector2::new(0.005, -0.015),
            max: Vector2::new(0.085, 0.045),
            top: 0.0,
            cell: 5.0e-4,
        },
        path: PathOptions::default(),
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: job::RAPID_SKIM,
    };
    let convention = robot
        .controller
        .ok_or("the KR 300's file declares KUKA's controller")?;
    let job =
        Job::new(robot.model.clone(), &robot.joint_limits, setup)?.with_controller(convention);
    let seed = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];

    // The spin: the program's loads once, then the shortest path over stations x spins.
    let o = SpinOptions::default();
    let loads = LoadPath::new(&job, &program, o.step, o.per_metre, o.per_second)?;
    let plan = spin::plan(&job, &loads, &seed, &o)?;
    let mm = |c: &spin::SpinCost| format!("RMS {:.4} mm, max {:.4} mm", c.rms * 1e3, c.max * 1e3);
    println!(
        "spin over {} stations x {} candidates:",
        plan.stations,
        plan.candidates.len()
    );
    if let Some(s) = &plan.seed {
        println!("  the seed's constant spin  {}", mm(s));
    }
    if let Some((a, c)) = &plan.best_constant {
        println!(
            "  the best constant spin    {} ({:.0} degrees)",
            mm(c),
            a.to_degrees()
        );
    }
    println!("  optimised along the path  {}", mm(&plan.optimised));
    let job = job.with_spin(plan.schedule);
    let report = job::run(&job, &program, &seed)?;
    println!(
        "path error max, uncompensated {:.3} mm, compensated {:.1e} m",
        report.path_error(false).max * 1e3,
        report.path_error(true).max
    );

    // KRL, both commands.
    let target = Target {
        model: job.model(),
        convention: job.controller(),
        robot: "the KR 300",
        placement: job.setup().placement,
        program: &program,
        rate_hz: report.rate_hz,
        rapid_speed: job.setup().path.rapid_speed,
    };
    for command in [Command::Cartesian, Command::Joints] {
        let files = robot_program::write(
            target,
            &report.samples,
            &ProgramOptions::new(Language::Krl, command),
        )?;
        let motions = files[0]
            .text
            .lines()
            .filter(|l| l.starts_with("LIN ") || l.starts_with("PTP "))
            .count();
        println!(
            "{} ({} motions), {}:",
            files[0].name,
            motions,
            command.name()
        );
        for line in files[0]
            .text
            .lines()
            .filter(|l| l.starts_with("LIN ") || l.starts_with("PTP "))
            .take(2)
        {
            println!("  {line}");
        }
    }

    // The placement: x, y +-0.15 m, z +-0.05 m, yaw +-30 degrees around the job's own.
    let problem = Problem::new(job.clone(), &program, &seed, o, false)?;
    let bx = PlacementBox {
        min: [2.30, -0.13, 0.87, -30f64.to_radians()],
        max: [2.60, 0.17, 0.97, 30f64.to_radians()],
        steps: [4, 4, 3, 3],
    };
    let found = placement::search(&bx, 3, |ps: &[[f64; 4]]| -> Result<_, ()> {
        Ok(problem.evaluate_all(ps, 2))
    })
    .map_err(|()| "unreachable")??;
    let (p, s) = found.best;
    println!(
        "best placement (the seed's spin, {} placements): x {:.3} m, y {:.3} m, z {:.3} m, yaw {:.1} degrees: RMS {:.4} mm",
        found.evaluations,
        p[0],
        p[1],
        p[2],
        p[3].to_degrees(),
        s.rms * 1e3
    );
    Ok(())
}
