//! `job` on a five-axis program: deflect-core's `machining::five_axis` pass, its summary, the
//! samples as CSV, the predicted parts as PLY meshes with the deviation along the surface's
//! normal, and their 3-D view.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use deflect_core::io::{job_out, ply};
use deflect_core::machining::dexel::surface::{DeviationStats, Face, SurfaceMesh};
use deflect_core::machining::five_axis::{self, Options, Report, ToolErrors};
use deflect_sim::SimError;
use deflect_sim::scenes::milling::part_view;
use serde_json::json;

use super::task::{JobTask, five_axis_options};
use crate::cli::JobArgs;
use crate::commands::stdout;

/// The part's figures: all machined points, and per face.
fn part_figures(
    points: &[deflect_core::machining::dexel::surface::SurfacePoint],
) -> serde_json::Value {
    let stats = |s: DeviationStats| {
        json!({
            "points": s.count,
            "max_left_mm": s.max_left * 1e3,
            "max_overcut_mm": s.max_overcut * 1e3,
            "rms_mm": s.rms * 1e3,
        })
    };
    let faces: serde_json::Map<String, serde_json::Value> = Face::ALL
        .iter()
        .filter_map(|f| {
            let s = DeviationStats::of(points.iter().filter(|p| Face::of(p) == *f));
            (s.count > 0).then(|| (f.name().to_string(), stats(s)))
        })
        .collect();
    json!({ "all": stats(DeviationStats::of(points)), "faces": faces })
}

fn tool_figures(e: &ToolErrors) -> serde_json::Value {
    json!({
        "max_position_mm": e.max_position * 1e3,
        "rms_position_mm": e.rms_position * 1e3,
        "max_axis_mrad": e.max_axis * 1e3,
        "line": e.line,
    })
}

/// The samples as CSV: time, line, the programmed tip and axis, the force, both tools'
/// errors.
fn samples_csv(r: &Report) -> String {
    let mut s = String::from(
        "time_s,line,x_mm,y_mm,z_mm,i,j,k,bands,fx_n,fy_n,fz_n,\
         uncompensated_tip_mm,uncompensated_axis_mrad,compensated_tip_mm,compensated_axis_mrad\n",
    );
    for x in &r.samples {
        let (p, a, f) = (x.path.position * 1e3, x.path.axis, x.force);
        let (ut, ua) = x.error(false);
        let (ct, ca) = x.error(true);
        let _ = writeln!(
            s,
            "{:.4},{},{:.6},{:.6},{:.6},{:.9},{:.9},{:.9},{},{:.4},{:.4},{:.4},{:.7},{:.6},{:.7},{:.6}",
            x.path.time,
            x.path.line,
            p.x,
            p.y,
            p.z,
            a.x,
            a.y,
            a.z,
            x.bands,
            f.x,
            f.y,
            f.z,
            ut * 1e3,
            ua * 1e3,
            ct * 1e3,
            ca * 1e3
        );
    }
    s
}

/// Runs the five-axis pass and writes its files.
pub fn five_axis_cmd(a: &JobArgs, t: &JobTask, out: &Path) -> Result<(), SimError> {
    let started = Instant::now();
    let options: Options = five_axis_options(a, t.shape);
    let r = five_axis::run(&t.job, &t.program, &t.seed, &options)
        .map_err(|e| SimError::new(format!("{}: {e}", t.program_name)))?;
    let pass = started.elapsed().as_secs_f64();
    let cell = t.job.setup().stock.cell;
    let fail = |e: deflect_core::TickError| SimError::new(format!("{}: {e}", t.program_name));
    let (eu, ec) = (r.errors(false), r.errors(true));
    // Ends matched within the farthest the tool's edge left the program (its tip, and its
    // tilt along the flutes) and two cells: no surface moves farther along its normal.
    let reach = eu.max_position + eu.max_axis * options.length + 2.0 * cell;
    let (pu, missing_u) = r
        .nominal
        .surface_deviation(&r.uncompensated, reach)
        .map_err(fail)?;
    let (pc, missing_c) = r
        .nominal
        .surface_deviation(&r.compensated, reach)
        .map_err(fail)?;
    let (fu, fc) = (part_figures(&pu), part_figures(&pc));
    let (su, sc) = (DeviationStats::of(&pu), DeviationStats::of(&pc));
    let mu = SurfaceMesh::new(pu, cell).map_err(fail)?;
    let mc = SurfaceMesh::new(pc, cell).map_err(fail)?;
    let mut files = write_meshes(out, &mu, &mc)?;
    plot_view(t, out, [(&su, &mu), (&sc, &mc)])?;
    files.push("part_view.png".into());
    let write = |name: &str, text: &str| {
        job_out::write(out.join(name), text).map_err(|e| SimError::new(e.to_string()))
    };
    write("five_axis_samples.csv", &samples_csv(&r))?;
    files.push("five_axis_samples.csv".into());
    let wall = started.elapsed().as_secs_f64();
    let cutting = r.samples.iter().filter(|s| s.bands > 0).count();
    let n = r.samples.len();
    let text = summary_text(
        t,
        &Figures {
            r: &r,
            n,
            cutting,
            wall,
            pass,
            tool: [&eu, &ec],
            part: [(&su, missing_u), (&sc, missing_c)],
        },
    );
    let summary = json!({
        "program": t.program_name,
        "robot": t.robot_name,
        "samples": n,
        "cutting_samples": cutting,
        "rate_hz": r.rate_hz,
        "ray_updates": r.ray_updates,
        "wall_s": wall,
        "samples_per_second": n as f64 / pass.max(1e-9),
        "cell_mm": cell * 1e3,
        "tool": {
            "uncompensated": tool_figures(&eu),
            "compensated": tool_figures(&ec),
        },
        "part": {
            "uncompensated": fu,
            "compensated": fc,
            "unmatched_points": [missing_u, missing_c],
        },
        "rapid_volume_mm3": r.rapid_volume * 1e9,
    });
    write("five_axis_summary.txt", &text)?;
    write(
        "five_axis_summary.json",
        &serde_json::to_string_pretty(&summary).map_err(|e| SimError::new(e.to_string()))?,
    )?;
    stdout(format_args!(
        "{text}outputs in {}: {}, five_axis_summary.{{txt,json}}\n",
        out.display(),
        files.join(", ")
    ))
}

/// Writes the predicted parts' PLY meshes (uncompensated, compensated); their file names.
fn write_meshes(out: &Path, mu: &SurfaceMesh, mc: &SurfaceMesh) -> Result<Vec<String>, SimError> {
    let mut files = Vec::new();
    for (name, mesh) in [("part_uncompensated.ply", mu), ("part_compensated.ply", mc)] {
        let path = out.join(name);
        let f = std::fs::File::create(&path)
            .map_err(|e| SimError::file(&path, "create the PLY mesh", e))?;
        ply::write(mesh, ply::Format::Binary, std::io::BufWriter::new(f))
            .map_err(|e| SimError::file(&path, "write the PLY mesh", e))?;
        files.push(name.to_string());
    }
    Ok(files)
}

/// Plots the machined surfaces' deviation along their normal (uncompensated, compensated,
/// each with its statistics) to `part_view.png`.
fn plot_view(
    t: &JobTask,
    out: &Path,
    [(su, mu), (sc, mc)]: [(&DeviationStats, &SurfaceMesh); 2],
) -> Result<(), SimError> {
    let short = Path::new(&t.program_name).file_name().map_or_else(
        || t.program_name.clone(),
        |n| n.to_string_lossy().into_owned(),
    );
    let label = |name: &str, s: &DeviationStats| {
        format!(
            "{name}: {:+.3} / {:+.3} mm (left / overcut), RMS {:.3} mm",
            s.max_left * 1e3,
            s.max_overcut * 1e3,
            s.rms * 1e3
        )
    };
    let (lu, lc) = (label("uncompensated", su), label("compensated offline", sc));
    let png = out.join("part_view.png");
    part_view::plot_part_view(
        &png,
        &format!(
            "{short} on {}: the machined surface's deviation along its normal",
            t.robot_name
        ),
        &[(&lu, mu), (&lc, mc)],
    )?;
    Ok(())
}

/// The pass's figures that the summary text reports.
struct Figures<'a> {
    r: &'a Report,
    /// Samples, and those that cut.
    n: usize,
    cutting: usize,
    /// Wall time of the whole command and of the pass \[s\].
    wall: f64,
    pass: f64,
    /// The tool's errors, uncompensated and compensated.
    tool: [&'a ToolErrors; 2],
    /// The parts' deviation and unmatched points, uncompensated and compensated.
    part: [(&'a DeviationStats, usize); 2],
}

/// The summary's text: the pass, the tool's and the part's errors, the spin and the rapids.
fn summary_text(t: &JobTask, f: &Figures<'_>) -> String {
    let Figures {
        r,
        n,
        cutting,
        wall,
        pass,
        tool: [eu, ec],
        part: [(su, missing_u), (sc, missing_c)],
    } = *f;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "five-axis job: {} on {}, {n} samples at {} Hz ({cutting} cutting), {} rays cut, in \
         {wall:.1} s ({:.0} samples/s for the pass)",
        t.program_name,
        t.robot_name,
        r.rate_hz,
        r.ray_updates,
        n as f64 / pass.max(1e-9)
    );
    for (name, e) in [("uncompensated", eu), ("compensated offline", ec)] {
        let _ = writeln!(
            text,
            "  {name:<20} tool off the program: tip max {:.4} mm (line {}), RMS {:.4} mm; axis \
             max {:.4} mrad",
            e.max_position * 1e3,
            e.line,
            e.rms_position * 1e3,
            e.max_axis * 1e3
        );
    }
    for (name, s, missing) in [
        ("uncompensated", &su, missing_u),
        ("compensated offline", &sc, missing_c),
    ] {
        let _ = writeln!(
            text,
            "  {name:<20} part along the normal: {:+.4} mm left, {:+.4} mm overcut, RMS {:.4} \
             mm over {} points ({missing} unmatched)",
            s.max_left * 1e3,
            s.max_overcut * 1e3,
            s.rms * 1e3,
            s.count
        );
    }
    if let Some((plan, seconds)) = &t.spin {
        let rms = |c: Option<deflect_core::machining::spin::SpinCost>| {
            c.map_or("unreachable".to_string(), |c| {
                format!("{:.4} mm", c.rms * 1e3)
            })
        };
        let _ = writeln!(
            text,
            "  spin about the tool axis (searched in {seconds:.1} s): predicted RMS deflection \
             {:.4} mm optimised, {} at the seed's spin",
            plan.optimised.rms * 1e3,
            rms(plan.seed)
        );
    }
    let spin_range = r
        .samples
        .iter()
        .map(|s| s.spin)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if spin_range.0 != 0.0 || spin_range.1 != 0.0 {
        let _ = writeln!(
            text,
            "  the tool turned about its axis by {:.1} .. {:.1} degrees",
            spin_range.0.to_degrees(),
            spin_range.1.to_degrees()
        );
    }
    if r.rapid_volume > 0.0 {
        let _ = writeln!(
            text,
            "  the program's rapids removed {:.1} mm^3 of stock",
            r.rapid_volume * 1e9
        );
    }
    text
}
