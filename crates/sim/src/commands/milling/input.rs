//! What `milling` reads and checks before any work: the groove, or a program with its arm,
//! setup and start joints.

use std::path::Path;

use deflect_core::SerialRobot;
use deflect_core::io::apt::AptCutter;
use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::machining::Program;
use deflect_core::machining::cutting::Tool;
use deflect_core::machining::five_axis::Options;
use deflect_core::machining::job::{Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::machining::profile::ToolShape;
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::units::LengthUnit;
use deflect_sim::scenes::milling::{MillingArm, program};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

use crate::cli::{CliError, MillingArgs};
use crate::commands::inputs::{apt_tools, load_arm, program_and_cutters, tool_and_material};

/// deflect's test workpiece after the paper's (grooves, a ramp, a circular pocket).
const TEST_WORKPIECE: &str = include_str!("../../../../../data/test_workpiece.nc");
/// Its stock [mm]: XMIN, YMIN, XMAX, YMAX.
const TEST_STOCK_MM: [f64; 4] = [0.0, 0.0, 140.0, 130.0];

/// What `milling` runs: the groove, or a program with its setup.
pub enum MillingInput {
    /// The straight groove with a prescribed force step.
    Groove,
    /// A program with its arm and setup.
    Program(Box<ProgramInput>),
}

/// A program run's inputs, checked.
pub struct ProgramInput {
    /// The program.
    pub program: Program,
    /// Its name in the outputs.
    pub name: String,
    /// The job's setup (placement, tool, material, stock, path).
    pub setup: Setup,
    /// Joints near the first pose \[rad\].
    pub q0: Vec<f64>,
    /// The arm.
    pub arm: MillingArm,
    /// The tools of an APT program's numbered `CUTTER/` statements (five-axis programs).
    pub tools: Option<deflect_core::machining::tools::ToolTable>,
    /// The setup's tool's end (five-axis programs): the program's first `CUTTER/`, or flat.
    pub shape: deflect_core::machining::profile::ToolShape,
}

/// Reads and checks the program, the stock and the placement before any work.
pub fn load(a: &MillingArgs) -> Result<MillingInput, CliError> {
    let options = GcodeOptions {
        start: Vector3::new(0.0, 0.0, 0.02),
        units: LengthUnit::Millimetre,
        ..GcodeOptions::default()
    };
    let mut cutters = Vec::new();
    let (program, name, builtin) = match a.program.as_deref() {
        Some("groove") if a.urdf.is_some() => {
            return Err(CliError::Usage(
                "--program groove runs the paper's KR 300 with a prescribed force; --urdf \
                 applies to programs"
                    .into(),
            ));
        }
        Some("groove") => return Ok(MillingInput::Groove),
        Some(path) => {
            let (program, c) = program_and_cutters("--program", Path::new(path), &options)?;
            cutters = c;
            (program, path.to_string(), false)
        }
        None => (
            gcode::from_str(TEST_WORKPIECE, &options)
                .map_err(|e| CliError::Failure(format!("built-in test workpiece: {e}")))?,
            "data/test_workpiece.nc (built in)".to_string(),
            true,
        ),
    };
    let (tool, coefficients) = tool_and_material(&a.tool)?;
    let (tool, shape) = setup_tool(tool, &cutters, &name)?;
    let tools = apt_tools(
        (
            a.tool.flutes,
            a.tool.helix.to_radians(),
            Options::default().length,
        ),
        &cutters,
        &name,
    )?;
    let files = load_arm(
        a.urdf.as_deref(),
        a.stiffness.as_deref(),
        a.base.as_deref(),
        a.tip.as_deref(),
    )?;
    let robot = &files.spec.robot;
    let dof = robot.model.dof();
    if dof < 6 {
        return Err(CliError::Failure(format!(
            "{}, tip {}: the chain has {dof} actuated joints; the machining job's pose IK \
             (the tool down the workpiece's z) needs at least 6",
            files.urdf_name, files.tip
        )));
    }
    let q0 = start_joints(a, robot)?;
    let arm_name = if files.builtin {
        "KR 300 R2500".to_string()
    } else {
        files.parsed.name.clone()
    };
    let arm = MillingArm::from_spec(&arm_name, files.spec, &files.parsed, &files.tip)
        .map_err(|e| CliError::Failure(format!("{}: {}", files.urdf_name, e.0)))?;
    let (min, max) = stock_corners(a, builtin, &program, tool.diameter, &name)?;
    let placement = placement(a, &program)?;
    let setup = Setup {
        placement,
        tool_orientation: Setup::tool_down(),
        tool,
        coefficients,
        stock: Stock {
            min,
            max,
            top: 0.0,
            cell: a.cell * 1e-3,
        },
        path: PathOptions {
            rate_hz: 1.0 / (a.cycle_ms * 1e-3),
            blending: a.blending()?,
            ..PathOptions::default()
        },
        ik: PoseIkOptions::default(),
        hand_spindle: None,
        rapid_skim: deflect_core::machining::job::RAPID_SKIM,
    };
    setup
        .validate()
        .map_err(|e| CliError::Usage(format!("--stock/--cell/--placement: {e}")))?;
    Ok(MillingInput::Program(Box::new(ProgramInput {
        program,
        name,
        setup,
        q0,
        arm,
        tools,
        shape,
    })))
}

/// The start joints (`--q0`, else the program seed) \[rad\], checked against the arm's
/// joints and limits.
fn start_joints(a: &MillingArgs, robot: &SerialRobot) -> Result<Vec<f64>, CliError> {
    let dof = robot.model.dof();
    let q0 = a.q0.clone().unwrap_or(program::PROGRAM_SEED.to_vec());
    if q0.len() != dof {
        return Err(CliError::Usage(format!(
            "--q0: {} values given; expected {dof} (one per actuated joint of {})",
            q0.len(),
            robot.joint_names.join(", ")
        )));
    }
    for (k, (&q, &(lo, hi))) in q0.iter().zip(&robot.joint_limits).enumerate() {
        if q < lo || q > hi {
            return Err(CliError::Usage(format!(
                "--q0: joint {k} ({}) is {q} rad: outside its limits [{lo}, {hi}] rad",
                robot.joint_names.get(k).map_or("?", String::as_str)
            )));
        }
    }
    Ok(q0)
}

/// The stock's corners (x, y) \[m\]: `--stock` \[mm\] (or the test workpiece's), else around
/// the program's feed moves with a tool of `tool_diameter` \[m\].
fn stock_corners(
    a: &MillingArgs,
    builtin: bool,
    program: &Program,
    tool_diameter: f64,
    name: &str,
) -> Result<(Vector2<f64>, Vector2<f64>), CliError> {
    Ok(match (&a.stock, builtin) {
        (Some(_), _) | (None, true) => {
            let s = a.stock.as_deref().unwrap_or(&TEST_STOCK_MM);
            match s {
                [x0, y0, x1, y1] if x1 > x0 && y1 > y0 => {
                    (Vector2::new(*x0, *y0) * 1e-3, Vector2::new(*x1, *y1) * 1e-3)
                }
                _ => {
                    return Err(CliError::Usage(format!(
                        "--stock {s:?}: expected XMIN < XMAX and YMIN < YMAX [mm]"
                    )));
                }
            }
        }
        (None, false) => Stock::around(program, tool_diameter / 2.0).ok_or_else(|| {
            CliError::Failure(format!(
                "{name}: no feed move (G1-G3) to size the stock from; give --stock"
            ))
        })?,
    })
}

/// The workpiece frame in the base frame: `--placement` x y z \[m\] roll pitch yaw \[rad\],
/// else the KR 300's default for the program.
fn placement(a: &MillingArgs, program: &Program) -> Result<Isometry3<f64>, CliError> {
    Ok(match a.placement.as_deref() {
        Some([x, y, z, r, p, w]) => Isometry3::from_parts(
            Translation3::new(*x, *y, *z),
            UnitQuaternion::from_euler_angles(*r, *p, *w),
        ),
        Some(_) => return Err(CliError::Usage("--placement: expected 6 values".into())),
        None if program.is_multi_axis() => {
            let [x, y, z, r, p, w] = crate::commands::job::KR300_FIVE_AXIS_PLACEMENT;
            Isometry3::from_parts(
                Translation3::new(x, y, z),
                UnitQuaternion::from_euler_angles(r, p, w),
            )
        }
        None => program::kr300_placement(),
    })
}

/// The setup's tool and its end: a five-axis program's cutters before any LOADTL are the
/// setup's tool (after one, a table), else `tool` (flat).
fn setup_tool(
    tool: Tool,
    cutters: &[AptCutter],
    name: &str,
) -> Result<(Tool, ToolShape), CliError> {
    let first = cutters.iter().rev().find(|c| c.tool == 0);
    let tool = match first {
        Some(c) => Tool::new(c.diameter, tool.flutes, tool.helix)
            .map_err(|e| CliError::Failure(format!("{name} line {}: CUTTER: {e}", c.line)))?,
        None => tool,
    };
    let shape = first.map_or(ToolShape::Flat, |c| c.shape);
    Ok((tool, shape))
}
