//! `delta`: the D'Alembert correction on a Delta robot ([`deflect_sim::scenes::delta`]):
//! static tests on a 3-D grid, the fitted map, a fast move uncorrected and corrected.

use std::fmt::Write as _;
use std::path::Path;

use deflect_core::io::map_json;
use deflect_sim::SimError;
use deflect_sim::scenes::delta::output::table;
use deflect_sim::scenes::delta::{self, DeltaOptions};

use super::Cmd;
use crate::cli::{CliError, DeltaArgs};

/// The options the command line sets.
pub fn options(a: &DeltaArgs) -> DeltaOptions {
    let d = DeltaOptions::default();
    let params = delta::DeltaParams {
        payload_mass: a.payload_mass,
        ..d.params
    };
    DeltaOptions {
        params,
        mass: params.platform_mass + params.payload_mass + 1.5 * params.forearm_mass,
        g: a.g,
        nodes: [a.nodes; 3],
        test_force: a.test_force,
        jobs: a.jobs,
        ..d
    }
}

/// The `delta` command: runs, prints the table, writes delta_summary.{txt,json},
/// delta_map.json (the fitted map, format_version 2) and delta_samples.csv.
fn run(a: &DeltaArgs, out: &Path) -> Result<(), SimError> {
    let r = delta::delta(&options(a))?;
    let text = table(&r);
    put!("{text}");
    let write = |file: &str, body: &str| {
        std::fs::write(out.join(file), body)
            .map_err(|e| SimError::file(&out.join(file), "write", e))
    };
    write("delta_summary.txt", &text)?;
    let json = serde_json::json!({
        "options": r.options,
        "static_rel_error": r.static_rel_error,
        "runs": r.runs,
        "wall_seconds": r.wall_seconds,
    });
    write(
        "delta_summary.json",
        &serde_json::to_string_pretty(&json).map_err(|e| SimError::new(e.to_string()))?,
    )?;
    write(
        "delta_map.json",
        &map_json::grid_to_string(&r.map).map_err(|e| SimError::new(e.to_string()))?,
    )?;
    let mut csv = String::from("run,time_s,x_m,y_m,z_m,actual_x_m,actual_y_m,actual_z_m\n");
    for run in &r.runs {
        for (t, d, p) in &run.samples {
            let _ = writeln!(
                csv,
                "{},{t},{},{},{},{},{},{}",
                if run.corrected {
                    "corrected"
                } else {
                    "uncorrected"
                },
                d[0],
                d[1],
                d[2],
                p[0],
                p[1],
                p[2]
            );
        }
    }
    write("delta_samples.csv", &csv)?;
    say!(
        "wrote {}/delta_summary.{{txt,json}}, delta_map.json, delta_samples.csv",
        out.display()
    );
    Ok(())
}

impl Cmd for DeltaArgs {
    type Input = ();

    fn load(&self) -> Result<(), CliError> {
        Ok(())
    }

    fn run(&self, (): (), out: &Path) -> Result<(), SimError> {
        run(self, out)
    }
}
