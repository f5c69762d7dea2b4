//! `milling --program` on a five-axis program: the testbed's runs of the five-axis pass
//! (deflect-sim's `scenes::milling::five_axis`), their summary, the parts as PLY meshes and
//! their 3-D view.

use std::fmt::Write as _;
use std::path::Path;

use deflect_core::io::{job_out, ply};
use deflect_core::machining::dexel::surface::{DeviationStats, SurfaceMesh};
use deflect_core::machining::five_axis::Options;
use deflect_core::machining::tools::ToolTable;
use deflect_sim::SimError;
use deflect_sim::scenes::milling::{self, five_axis, part_view};
use serde_json::json;

use super::input::ProgramInput;
use crate::commands::stdout;

/// Runs the scenario and writes `milling_summary.{txt,json}`, `milling_part_<mode>.ply` and
/// `milling_part_view.png`.
pub fn run_and_write(
    opts: &milling::MillingOptions,
    p: &ProgramInput,
    tools: Option<&ToolTable>,
    options: &Options,
    out: &Path,
) -> Result<(), SimError> {
    let r =
        five_axis::milling_five_axis(opts, &p.arm, &p.program, &p.setup, tools, options, &p.q0)?;
    let cell = p.setup.stock.cell;
    let e = r.offline.errors(false);
    let reach = e.max_position + e.max_axis * options.length + 2.0 * cell;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "five-axis program {} on {} in rapier ({} samples at {} Hz, {:.1} s):",
        p.name,
        r.robot,
        r.offline.samples.len(),
        r.offline.rate_hz,
        r.wall_seconds
    );
    let mut runs = Vec::new();
    let mut meshes = Vec::new();
    for run in &r.runs {
        let (points, missing) = r
            .offline
            .nominal
            .surface_deviation(&run.part, reach)
            .map_err(|e| SimError::new(format!("{}: {e}", p.name)))?;
        let s = DeviationStats::of(&points);
        let _ = writeln!(
            text,
            "  {:<14} tool off the program: tip max {:.4} mm, RMS {:.4} mm, axis max {:.3} mrad; \
             part along the normal: {:+.4} / {:+.4} mm, RMS {:.4} mm ({missing} unmatched)",
            run.mode.label(),
            run.max_tip * 1e3,
            run.rms_tip * 1e3,
            run.max_axis * 1e3,
            s.max_left * 1e3,
            s.max_overcut * 1e3,
            s.rms * 1e3
        );
        runs.push(json!({
            "mode": run.mode.label(),
            "max_tip_mm": run.max_tip * 1e3,
            "rms_tip_mm": run.rms_tip * 1e3,
            "max_axis_mrad": run.max_axis * 1e3,
            "part": {
                "points": s.count,
                "max_left_mm": s.max_left * 1e3,
                "max_overcut_mm": s.max_overcut * 1e3,
                "rms_mm": s.rms * 1e3,
                "unmatched": missing,
            },
        }));
        let label = format!(
            "{}: {:+.3} / {:+.3} mm (left / overcut), RMS {:.3} mm",
            run.mode.label(),
            s.max_left * 1e3,
            s.max_overcut * 1e3,
            s.rms * 1e3
        );
        let mesh = SurfaceMesh::new(points, cell).map_err(|e| SimError::new(e.to_string()))?;
        let path = out.join(format!("milling_part_{}.ply", run.mode.label()));
        write_ply(&path, &mesh)?;
        meshes.push((label, mesh));
    }
    plot_view(p, &r.robot, &meshes, out)?;
    let write = |name: &str, body: &str| {
        job_out::write(out.join(name), body).map_err(|e| SimError::new(e.to_string()))
    };
    write("milling_summary.txt", &text)?;
    let summary = json!({
        "program": p.name,
        "robot": r.robot,
        "samples": r.offline.samples.len(),
        "wall_s": r.wall_seconds,
        "runs": runs,
    });
    write(
        "milling_summary.json",
        &serde_json::to_string_pretty(&summary).map_err(|e| SimError::new(e.to_string()))?,
    )?;
    stdout(format_args!(
        "{text}wrote {}/milling_summary.{{txt,json}}, milling_part_<mode>.ply, milling_part_view.png\n",
        out.display()
    ))
}

/// Writes `mesh` to `path` as a binary PLY.
fn write_ply(path: &Path, mesh: &SurfaceMesh) -> Result<(), SimError> {
    let f =
        std::fs::File::create(path).map_err(|e| SimError::file(path, "create the PLY mesh", e))?;
    ply::write(mesh, ply::Format::Binary, std::io::BufWriter::new(f))
        .map_err(|e| SimError::file(path, "write the PLY mesh", e))?;
    Ok(())
}

/// Plots the runs' machined surfaces (`meshes`, with their labels) to `milling_part_view.png`.
fn plot_view(
    p: &ProgramInput,
    robot: &str,
    meshes: &[(String, SurfaceMesh)],
    out: &Path,
) -> Result<(), SimError> {
    let panels: Vec<(&str, &SurfaceMesh)> = meshes.iter().map(|(l, m)| (l.as_str(), m)).collect();
    let short = Path::new(&p.name)
        .file_name()
        .map_or_else(|| p.name.clone(), |n| n.to_string_lossy().into_owned());
    part_view::plot_part_view(
        &out.join("milling_part_view.png"),
        &format!(
            "{short}, {} in rapier: the machined surface along its normal",
            robot
        ),
        &panels,
    )?;
    Ok(())
}
