//! Calibration of the parallel robot as the paper does it (Paksoy, Dede and Kiper (2025),
//! sec. 3.1-3.2, Eq. 9-14): simulated static tests, the fitted compliance map and its
//! held-out error, one thread per mechanism; what the `reproduce`, `run`, `fit` and
//! `static-test` commands share.

use std::path::Path;

use super::params::{Constraint, Head, RobotParams};
use super::run::{self, StaticOptions, StaticReading};
use crate::workers::{parallel_map, progress};
use crate::{SimError, write_file};
use deflect_core::compliance_map::ComplianceMap;
use deflect_core::io::map_json;
use indicatif::ProgressBar;

/// The header of the static-test CSV: units in the column names.
pub const STATIC_HEADER: &str = "x_mm,y_mm,force_axis,force_N,dx_mm,dy_mm";

/// `v` rounded to `decimals` and written without float noise or a negative zero:
/// -75.00000000000001 -> "-75", 172.132 -> "172.132".
pub fn plain(v: f64, decimals: i32) -> String {
    let k = 10f64.powi(decimals);
    let r = (v * k).round() / k;
    if r == 0.0 {
        "0".to_string()
    } else {
        format!("{r}")
    }
}

/// The static-test readings as CSV ([`STATIC_HEADER`]: mm, N), the columns `static-test`
/// writes and `fit` reads; positions to 1 nm, forces to 1 uN, displacements to 1e-9 mm.
pub fn static_csv(readings: &[StaticReading]) -> String {
    let mut s = format!("{STATIC_HEADER}\n");
    for r in readings {
        s.push_str(&format!(
            "{},{},{},{},{},{}\n",
            plain(r.x * 1e3, 6),
            plain(r.y * 1e3, 6),
            if r.axis == 0 { "x" } else { "y" },
            plain(r.force, 6),
            plain(r.d[0] * 1e3, 9),
            plain(r.d[1] * 1e3, 9),
        ));
    }
    s
}

/// Static tests + fit + held-out for one mechanism; writes its files; returns the map and a
/// printable summary.
fn calibrate(
    constraint: Constraint,
    out: &Path,
    pb: &ProgressBar,
) -> Result<(ComplianceMap, String), SimError> {
    let params = RobotParams::new(constraint, Head::Upper);
    let opts = StaticOptions::default();
    let readings = run::static_tests(&params, &opts, || pb.inc(1))?;
    let tag = constraint.label().to_lowercase();
    write_file(
        &out.join(format!("static_tests_{tag}.csv")),
        "the static-test CSV",
        static_csv(&readings),
    )?;
    let (worst_small, rms_small) = run::linear_agreement(&readings, 50.0);
    let (worst, rms) = run::linear_agreement(&readings, f64::INFINITY);
    let dmax = readings
        .iter()
        .map(|r| (r.d[0].powi(2) + r.d[1].powi(2)).sqrt())
        .fold(0.0, f64::max);
    let mut text = format!(
        "{}: static tests, 15 nodes x 2 axes x 5 forces: up to {:.3} mm at 245 N; vs J K^-1 J^T \
         (relative): at 49 N worst {:.1e} RMS {:.1e}, up to 245 N worst {:.1e} RMS {:.1e}\n",
        constraint.label(),
        dmax * 1e3,
        worst_small,
        rms_small,
        worst,
        rms
    );
    let map = run::fit_map(&readings)?;
    write_file(
        &out.join(format!("compliance_map_{tag}.json")),
        "the compliance map JSON",
        map_json::to_string(&map)?,
    )?;
    let ho = run::held_out(&params, &map, &opts)?;
    pb.inc(1);
    text.push_str(&format!(
        "{}: map held-out error: cell centres (fresh static tests, 245 N) RMS {:.4} mm, max \
         {:.4} mm (RMS displacement there {:.3} mm); leave-one-line-out RMS y {:.4} mm, x {:.4} mm",
        constraint.label(),
        ho.centre_rms * 1e3,
        ho.centre_max * 1e3,
        ho.centre_rms_displacement * 1e3,
        ho.loo_rms_y * 1e3,
        ho.loo_rms_x * 1e3
    ));
    write_file(
        &out.join(format!("held_out_{tag}.json")),
        "the held-out JSON",
        serde_json::to_string_pretty(&ho)?,
    )?;
    Ok((map, text))
}

/// The calibration of each of several mechanisms, one thread each: per mechanism, in order,
/// its map and its summary text (for the command to print).
pub fn calibrate_all(
    constraints: &[Constraint],
    out: &Path,
) -> Result<Vec<(Constraint, ComplianceMap, String)>, SimError> {
    let pb = progress(31 * constraints.len(), "static tests");
    let results = parallel_map(constraints, constraints.len(), |c| calibrate(*c, out, &pb))?;
    pb.finish_and_clear();
    let mut maps = Vec::new();
    for (c, r) in constraints.iter().zip(results) {
        let (map, text) = r?;
        maps.push((*c, map, text));
    }
    Ok(maps)
}
