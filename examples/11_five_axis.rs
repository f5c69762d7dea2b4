//! Example 11: a five-axis program in: ball-end finishing across a tilted plane and a swarf
//! cut along a leaning wall (`data/five_axis_finish.apt`), read with its tool axes and cutters;
//! the ball end's cutting wrench with the tool leaning 10 degrees to the feed; the program cut
//! into a tri-dexel stock, each operation with its own cutter; then the five-axis job on the
//! KR 300: the tool axis in every pose, the force along each cutter's edge, the tip and the
//! tilt compensated, and the parts predicted along the surface's normal.
//! Prints the program's operations and tilts, the wrench, the volumes removed, the tools'
//! errors and the parts' deviations.
//!
//! Run: `cargo run --release --example 11_five_axis`

use deflect_core::SerialRobot;
use deflect_core::io::apt;
use deflect_core::io::gcode::GcodeOptions;
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::dexel::surface::DeviationStats;
use deflect_core::machining::dexel::{DexelTool, Dexels};
use deflect_core::machining::five_axis::{self, Options};
use deflect_core::machining::job::{self, Job, Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::profile::{self, Band, Cut, Profile};
use deflect_core::machining::tools::{ToolSpec, ToolTable};
use deflect_core::machining::{Motion, Program};
use deflect_core::mechanism::PoseIkOptions;
use nalgebra::{Isometry3, Vector2, Vector3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/five_axis_finish.apt");
    let apt = apt::from_path(path, &GcodeOptions::default())?;
    let program = &apt.program;
    let tilt = |m: &deflect_core::machining::Move| m.end_axis.z.acos().to_degrees();
    println!(
        "{} moves, {} operations",
        program.moves.len(),
        program.operations.len()
    );
    for (k, op) in program.operations.iter().enumerate() {
        let end = program
            .operations
            .get(k + 1)
            .map_or(program.moves.len(), |o| o.first_move);
        let moves = program.moves.get(op.first_move..end).unwrap_or(&[]);
        let (lo, hi) = moves
            .iter()
            .map(tilt)
            .fold((f64::MAX, f64::MIN), |(a, b), t| (a.min(t), b.max(t)));
        println!(
            "  {:<28} moves {:>3}..{:<3} tool axis {lo:.1}..{hi:.1} deg from +z",
            op.name, op.first_move, end
        );
    }
    for c in &apt.cutters {
        println!(
            "  cutter of T{}: {} mm {}",
            c.tool,
            c.diameter * 1e3,
            c.shape.name()
        );
    }

    // The ball end on the first finishing line: 0.1 mm per tooth along the move, the tool
    // leaning to it; engaged 0.3 mm deep (the allowance) over the front half.
    let first = program
        .moves
        .iter()
        .find(|m| {
            // Along the surface: the move mostly across the tool axis.
            let d = m.end - m.start;
            m.is_feed() && m.start_axis == m.end_axis && d.dot(&m.end_axis).abs() < 0.5 * d.norm()
        })
        .ok_or("no finishing move")?;
    let ball_cutter = apt.cutters.first().ok_or("no cutter")?;
    let ball = Profile::new(
        &Tool::new(ball_cutter.diameter, 2, 30f64.to_radians())?,
        ball_cutter.shape,
    )?;
    let feed = profile::tool_feed(&first.end_axis, &first.tangent(0.5), 0.1e-3)
        .ok_or("feed along the axis")?;
    let bands = [Band::new(0.3e-3, 0.0, std::f64::consts::PI)];
    let w = profile::average(
        &Coefficients::AL7075_T6_CARBIDE,
        &ball,
        &Cut {
            bands: &bands,
            feed,
        },
    )?;
    println!(
        "ball end, lead {:.1} deg: force ({:.1}, {:.1}, {:.1}) N, torque {:.3} N m (tool frame)",
        feed.z.atan2(feed.x).to_degrees(),
        w.force.x,
        w.force.y,
        w.force.z,
        w.moment.z
    );

    // The stock: a block under the plane and around the wall, 2 mm rays.
    let mut stock = Dexels::block(
        Vector3::new(-6e-3, -16e-3, -12e-3),
        Vector3::new(56e-3, 26e-3, 10e-3),
        2e-3,
    )?;
    let before = stock.volume();
    for (k, op) in program.operations.iter().enumerate() {
        let end = program
            .operations
            .get(k + 1)
            .map_or(program.moves.len(), |o| o.first_move);
        let cutter = apt
            .cutters
            .get(k)
            .ok_or("an operation without its cutter")?;
        let tool = DexelTool::new(
            &Profile::new(&Tool::new(cutter.diameter, 2, 0.0)?, cutter.shape)?,
            15e-3,
        )?;
        let part = Program {
            moves: program
                .moves
                .get(op.first_move..end)
                .unwrap_or(&[])
                .iter()
                .filter(|m| !matches!(m.motion, Motion::Rapid))
                .copied()
                .collect(),
            operations: Vec::new(),
        };
        // Each feed stretch is a path of its own (the rapids between are left out).
        let mut removed = 0.0;
        for m in &part.moves {
            let one = Program {
                moves: vec![*m],
                operations: Vec::new(),
            };
            removed += stock.cut_program(&tool, &one)?.volume;
        }
        println!("  {:<28} removed {:.0} mm^3", op.name, removed * 1e9);
    }
    println!(
        "stock {:.0} -> {:.0} mm^3",
        before * 1e9,
        stock.volume() * 1e9
    );

    // The job on the KR 300: the table low and close (the wrist stays bent as the tool
    // tilts), each operation's cutter from its CUTTER statement, 0.5 mm rays.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/");
    let robot = SerialRobot::from_path(
        format!("{dir}robots/kr300/kr300_r2500.urdf"),
        format!("{dir}robots/kr300/kr300_r2500_stiffness.toml"),
        "tcp",
    )?;
    let mut tools = Vec::new();
    for c in &apt.cutters {
        tools.push(ToolSpec {
            number: c.tool,
            tool: Tool::new(c.diameter, 2, 0.0)?,
            shape: c.shape,
            length: 0.0,
            name: String::new(),
        });
    }
    let setup = Setup {
        placement: Isometry3::new(
            Vector3::new(2.0, 0.0, 0.4),
            Vector3::new(0.0, 0.0, std::f64::consts::PI),
        ),
        tool_orientation: Setup::tool_down(),
        tool: Tool::new(0.01, 2, 0.0)?,
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min: Vector2::new(-0.006, -0.016),
            max: Vector2::new(0.056, 0.026),
            top: 0.0,
            cell: 5e-4,
        },
        path: PathOptions::default(),
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: job::RAPID_SKIM,
    };
    let job = Job::new(robot.model.clone(), &robot.joint_limits, setup)?
        .with_tools(ToolTable::new(tools)?);
    let seed = [0.0, -0.9, 1.4, 0.0, -0.5, 0.0];
    let options = Options {
        depth: 0.02,
        ..Options::default()
    };
    let r = five_axis::run(&job, program, &seed, &options)?;
    for (name, compensated) in [("uncompensated", false), ("compensated", true)] {
        let e = r.errors(compensated);
        let stock = if compensated {
            &r.compensated
        } else {
            &r.uncompensated
        };
        let (points, _) = r.nominal.surface_deviation(stock, 3e-3)?;
        let s = DeviationStats::of(&points);
        println!(
            "{name:<13} tool: tip max {:.4} mm, axis max {:.4} mrad; part: {:+.4} / {:+.4} mm, RMS {:.4} mm",
            e.max_position * 1e3,
            e.max_axis * 1e3,
            s.max_left * 1e3,
            s.max_overcut * 1e3,
            s.rms * 1e3
        );
    }
    Ok(())
}
