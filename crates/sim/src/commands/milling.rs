//! `milling`: the hybrid compensation of Hähn and Weigold (sec. 2.2-2.6, 3). By default the
//! paper's validation: deflect's test workpiece (or `--program`) cut by the flexible KR 300
//! five ways ([`deflect_sim::scenes::milling::program`]); `--program groove` runs the straight
//! groove with a prescribed force step ([`deflect_sim::scenes::milling::run`]) with the
//! command line's feed, force, timing and noise settings. Prints the summary table and writes
//! its files.

use std::path::Path;

use deflect_core::io::gcode::{self, GcodeOptions};
use deflect_core::machining::Program;
use deflect_core::machining::cutting::{Coefficients, Tool};
use deflect_core::machining::job::{Setup, Stock};
use deflect_core::machining::path::PathOptions;
use deflect_core::mechanism::PoseIkOptions;
use deflect_core::units::LengthUnit;
use deflect_sim::SimError;
use deflect_sim::scenes::milling::program;
use deflect_sim::scenes::milling::program_output;
use deflect_sim::scenes::milling::{self, output, part_map};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::job::default_stock;
use super::serial::read_text;
use crate::cli::{CliError, MillingArgs};

/// deflect's test workpiece after the paper's (grooves, a ramp, a circular pocket).
const TEST_WORKPIECE: &str = include_str!("../../../../data/test_workpiece.nc");
/// Its stock [mm]: XMIN, YMIN, XMAX, YMAX.
const TEST_STOCK_MM: [f64; 4] = [0.0, 0.0, 140.0, 130.0];

/// What `milling` runs: the groove, or a program with its setup.
pub enum MillingInput {
    /// The straight groove with a prescribed force step.
    Groove,
    /// A program, its name, the job's setup and the start joints.
    Program(Box<(Program, String, Setup, Vec<f64>)>),
}

/// Reads and checks the program, the stock and the placement before any work.
pub fn load(a: &MillingArgs) -> Result<MillingInput, CliError> {
    let options = GcodeOptions {
        start: Vector3::new(0.0, 0.0, 0.02),
        units: LengthUnit::Millimetre,
    };
    let (program, name, builtin) = match a.program.as_deref() {
        Some("groove") => return Ok(MillingInput::Groove),
        Some(path) => {
            let p = Path::new(path);
            let text = read_text("--program", p, "G-code program")?;
            let program = gcode::from_str(&text, &options)
                .map_err(|e| CliError::Failure(format!("--program {path}: {e}")))?;
            (program, path.to_string(), false)
        }
        None => (
            gcode::from_str(TEST_WORKPIECE, &options)
                .map_err(|e| CliError::Failure(format!("built-in test workpiece: {e}")))?,
            "data/test_workpiece.nc (built in)".to_string(),
            true,
        ),
    };
    let tool = Tool::new(0.016, 3, 0.0).map_err(|e| CliError::Failure(e.to_string()))?;
    let (min, max) = match (&a.stock, builtin) {
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
        (None, false) => default_stock(&program, 0.008).ok_or_else(|| {
            CliError::Failure(format!(
                "{name}: no feed move (G1-G3) to size the stock from; give --stock"
            ))
        })?,
    };
    let placement = match a.placement.as_deref() {
        Some([x, y, z, r, p, w]) => Isometry3::from_parts(
            Translation3::new(*x, *y, *z),
            UnitQuaternion::from_euler_angles(*r, *p, *w),
        ),
        Some(_) => return Err(CliError::Usage("--placement: expected 6 values".into())),
        None => program::kr300_placement(),
    };
    let setup = Setup {
        placement,
        tool_orientation: Setup::tool_down(),
        tool,
        coefficients: Coefficients::AL7075_T6_CARBIDE,
        stock: Stock {
            min,
            max,
            top: 0.0,
            cell: a.cell * 1e-3,
        },
        path: PathOptions {
            rate_hz: 1.0 / (a.cycle_ms * 1e-3),
            ..PathOptions::default()
        },
        ik: PoseIkOptions::default(),
    };
    setup
        .validate()
        .map_err(|e| CliError::Usage(format!("--stock/--cell/--placement: {e}")))?;
    let q0 = a.q0.clone().unwrap_or(program::PROGRAM_SEED.to_vec());
    Ok(MillingInput::Program(Box::new((program, name, setup, q0))))
}

/// The options the command line sets.
fn options(a: &MillingArgs) -> milling::MillingOptions {
    let mut opts = milling::MillingOptions::default();
    let dir = nalgebra::Vector3::from(opts.force).normalize();
    opts.force = (dir * a.force).into();
    opts.feed = a.feed * 1e-3;
    opts.cut = a.cut;
    opts.cycle = a.cycle_ms * 1e-3;
    opts.force_rise = a.rise_ms * 1e-3;
    opts.estimate_lead = a.lead_ms * 1e-3;
    opts.estimate_error = a.estimate_error;
    opts.seed = a.seed;
    opts.id_poses = a.id_poses;
    opts.jobs = a.jobs;
    opts
}

/// The `milling` command (arguments checked by [`MillingArgs::check`], inputs by [`load`]).
pub fn milling_cmd(a: &MillingArgs, input: &MillingInput, out: &Path) -> Result<(), SimError> {
    let opts = options(a);
    let MillingInput::Program(p) = input else {
        let r = milling::milling(&opts)?;
        let table = output::table(&r);
        put!("{table}");
        output::write_all(out, &r)?;
        say!(
            "wrote {}/milling_summary.{{txt,csv,json}}, milling.mcap, milling_error.png, milling_stiffness.png",
            out.display()
        );
        return Ok(());
    };
    let (program, name, setup, q0) = p.as_ref();
    let r = program::milling_program(&opts, program, setup, q0)?;
    let text = program_output::table(name, &r);
    put!("{text}");
    let write = |file: &str, body: &str| {
        std::fs::write(out.join(file), body)
            .map_err(|e| SimError::file(&out.join(file), "write", e))
    };
    write("milling_summary.txt", &text)?;
    write(
        "milling_summary.json",
        &serde_json::to_string_pretty(&program_output::json(name, &r))
            .map_err(|e| SimError::new(e.to_string()))?,
    )?;
    write("milling_samples.csv", &program_output::csv(&r))?;
    program_output::write_mcap(&out.join("milling.mcap"), name, &r)?;
    for run in &r.runs {
        let e = &run.part_error;
        let label = format!(
            "{}: floors max {:.3} mm, RMS {:.3} mm; walls {:.0} mm^2 left, {:.0} overcut",
            run.mode.label(),
            e.floor.max * 1e3,
            e.floor.rms * 1e3,
            e.material_left * 1e6,
            e.overcut * 1e6
        );
        part_map::plot_part_deviation(
            &out.join(format!("milling_part_{}.png", run.mode.label())),
            &format!("{name}, KR 300 in rapier: the part's height above the nominal one"),
            &r.offline.nominal,
            &[(&label, &run.part)],
            setup.stock.top,
        )?;
    }
    say!(
        "wrote {}/milling_summary.{{txt,json}}, milling_samples.csv, milling.mcap, milling_part_<run>.png",
        out.display()
    );
    Ok(())
}
