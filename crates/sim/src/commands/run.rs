//! `run`: one motion on one configuration, uncorrected and/or corrected with the D'Alembert
//! correction (Paksoy, Dede and Kiper (2025), sec. 3.3, Eq. 5); prints its figures and writes
//! an MCAP log, a plot and the runs as JSON.

use std::path::Path;
use std::time::Instant;

use deflect_core::compliance_map::ComplianceMap;
use deflect_core::io::map_json;
use deflect_sim::scenes::parallel::output;
use deflect_sim::scenes::parallel::params::RobotParams;
use deflect_sim::scenes::parallel::run::{self, RunOptions, RunResult};
use deflect_sim::{SimError, write_file};

use super::Cmd;
use super::calibrate_all;
use super::inputs::{input_file, load_error};
use crate::cli::{CliError, Correction, RunArgs};

/// What `run --map` expects.
const MAP: &str = "compliance map JSON written by `fit` or static-test CSV written by \
                   `static-test`";

/// A map given by `run --map` and what the file was.
#[derive(Debug)]
pub struct LoadedMap {
    /// The map.
    pub map: ComplianceMap,
    /// "compliance map JSON" or "static-test CSV (fitted)".
    pub kind: &'static str,
}

/// Loads the map of `run --map` before any work (checked even with `--correction off`): a
/// JSON of `fit` (the file's first non-blank character is `{`) or a static-test CSV, fitted
/// as `fit --input` does.
pub fn load_map(path: &Path) -> Result<LoadedMap, CliError> {
    input_file("--map", path, MAP)?;
    let mut head = [0u8; 256];
    let n = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read(&mut f, &mut head))
        .map_err(|e| {
            let io = deflect_core::LoadError::Io {
                path: path.display().to_string(),
                message: e.to_string(),
            };
            load_error("--map", path, MAP, io)
        })?;
    let json = head
        .get(..n)
        .unwrap_or_default()
        .iter()
        .find(|b| !b.is_ascii_whitespace())
        .is_some_and(|&b| b == b'{');
    if json {
        const WHAT: &str = "compliance map JSON written by `fit` (the file starts with `{`)";
        let map = map_json::from_path(path).map_err(|e| load_error("--map", path, WHAT, e))?;
        Ok(LoadedMap {
            map,
            kind: "compliance map JSON",
        })
    } else {
        const WHAT: &str = "static-test CSV written by `static-test` (columns x_mm, y_mm, \
                            force_axis, force_N, dx_mm, dy_mm, or the older x, y, force_axis, \
                            force, dx, dy in mm and N; a JSON map starts with `{`)";
        let map = super::fit::fit_csv(path).map_err(|e| load_error("--map", path, WHAT, e))?;
        Ok(LoadedMap {
            map,
            kind: "static-test CSV (fitted)",
        })
    }
}

/// The `run` command; `map` is the loaded `--map`, if given.
fn run(args: &RunArgs, map: Option<LoadedMap>, out: &Path) -> Result<(), SimError> {
    if let (Some(m), Some(p)) = (&map, &args.map) {
        say!(
            "--map {}: {}, {} x {} nodes",
            p.display(),
            m.kind,
            m.map.x().len(),
            m.map.y().len()
        );
    }
    let map = map.map(|m| m.map);
    let head = args.head.head();
    let constraint = args.mechanism.constraint();
    let params = RobotParams::new(constraint, head);
    let motion = args.motion.motion();
    let map = if args.correction == Correction::Off {
        None
    } else if map.is_some() {
        map
    } else {
        calibrate_all(&[constraint], out)?.pop().map(|(_, m)| m)
    };
    let opts = RunOptions {
        mass: args.mass,
        ..Default::default()
    };
    let mut runs = Vec::new();
    for corrected in [false, true] {
        let wanted = match args.correction {
            Correction::Off => !corrected,
            Correction::On => corrected,
            Correction::Both => true,
        };
        if wanted {
            let t = Instant::now();
            let r = run::run(
                &params,
                motion,
                args.g,
                map.as_ref().filter(|_| corrected),
                &opts,
            )?;
            let sim = r.samples.last().map_or(0.0, |s| s.t);
            say!(
                "{} {} {} g {}: max path dev {:.4} mm, RMS {:.4} mm, area {:.4} mm2, length dev \
                 {:.4} mm, max tracking {:.4} mm ({:.1}x real time)",
                r.config,
                motion.label(),
                r.g,
                if corrected {
                    "corrected"
                } else {
                    "uncorrected"
                },
                r.metrics.max_dev_mm,
                r.metrics.rms_dev_mm,
                r.metrics.area_mm2,
                r.metrics.length_dev_mm,
                r.metrics.max_track_mm,
                sim / t.elapsed().as_secs_f64()
            );
            runs.push(r);
        }
    }
    let refs: Vec<&RunResult> = runs.iter().collect();
    let name = format!(
        "run_{}_{}_{}_{}g",
        constraint.label().to_lowercase(),
        head.label().to_lowercase(),
        motion.label(),
        args.g
    );
    let mcap_path = out.join(format!("{name}.mcap"));
    let n = output::write_mcap(&mcap_path, "run", &refs)?;
    output::plot_paths(&out.join(format!("{name}.png")), &refs)?;
    write_file(
        &out.join(format!("{name}.json")),
        "the runs JSON",
        serde_json::to_string_pretty(&runs)?,
    )?;
    say!("{} messages in {}", n, mcap_path.display());
    Ok(())
}

impl Cmd for RunArgs {
    type Input = Option<LoadedMap>;

    fn load(&self) -> Result<Option<LoadedMap>, CliError> {
        self.map.as_deref().map(load_map).transpose()
    }

    fn run(&self, input: Option<LoadedMap>, out: &Path) -> Result<(), SimError> {
        run(self, input, out)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A static-test table on a 3 x 5 grid (mm, N), displacement linear in the force.
    fn static_table() -> String {
        let mut s = String::from("x,y,force_axis,force,dx,dy\n");
        for i in 0..3 {
            for j in 0..5 {
                let (x, y) = (122.132 + 50.0 * f64::from(i), -75.0 + 37.5 * f64::from(j));
                for axis in ["x", "y"] {
                    for f in [49.05, 98.1, 147.15] {
                        let c = 1e-3 * (1.0 + 0.1 * f64::from(i) + 0.05 * f64::from(j));
                        let (dx, dy) = if axis == "x" {
                            (c * f, 0.1 * c * f)
                        } else {
                            (0.1 * c * f, 2.0 * c * f)
                        };
                        s.push_str(&format!("{x},{y},{axis},{f},{dx:e},{dy:e}\n"));
                    }
                }
            }
        }
        s
    }

    #[test]
    fn map_accepts_the_static_test_csv_and_the_json_and_says_which() {
        let dir = std::env::temp_dir().join(format!("deflect-sim-map-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let csv = dir.join("static.csv");
        std::fs::write(&csv, static_table()).unwrap();
        let fitted = load_map(&csv).unwrap();
        assert_eq!(fitted.kind, "static-test CSV (fitted)");
        assert_eq!((fitted.map.x().len(), fitted.map.y().len()), (3, 5));
        // The JSON of that map, with leading blanks, reads back as the same map.
        let json = dir.join("map.json");
        std::fs::write(
            &json,
            format!("\n  {}", map_json::to_string(&fitted.map).unwrap()),
        )
        .unwrap();
        let read = load_map(&json).unwrap();
        assert_eq!(read.kind, "compliance map JSON");
        let (p, f) = ([0.2, 0.0], [0.0, -245.0]);
        let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
        read.map.displacement(p, &f, &mut a).unwrap();
        fitted.map.displacement(p, &f, &mut b).unwrap();
        assert!(a[1].abs() > 1e-4, "{a:?}");
        assert_eq!(a, b);
        // The header with units (what `static-test` writes) and in metres give the same map.
        let units = dir.join("units.csv");
        let text = static_table().replacen(
            "x,y,force_axis,force,dx,dy",
            deflect_sim::scenes::parallel::calibrate::STATIC_HEADER,
            1,
        );
        std::fs::write(&units, text).unwrap();
        let with_units = load_map(&units).unwrap();
        let mut c = [0.0; 2];
        with_units.map.displacement(p, &f, &mut c).unwrap();
        assert_eq!(a, c);
        let (h, unit) =
            super::super::fit::unit_header("x_m,y_m,force_axis,force_N,dx_m,dy_m").unwrap();
        assert_eq!(
            h,
            "x,y,force,axis".replace("force,axis", "force_axis,force,dx,dy")
        );
        assert_eq!(unit, deflect_core::units::LengthUnit::Metre);
        assert!(super::super::fit::unit_header("x,y,force_axis,force,dx,dy").is_none());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
