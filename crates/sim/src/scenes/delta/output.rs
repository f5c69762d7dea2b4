//! The Delta scene's summary table.

use std::fmt::Write as _;

use super::run::DeltaResult;

/// The summary table.
pub fn table(r: &DeltaResult) -> String {
    let o = &r.options;
    let d = o.params.delta;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "delta: Delta robot (base radius {} m, platform {} m, arm {} m, forearm {} m, drives {:.0} \
         N m/rad) in rapier; static compliance vs J K^-1 J^T: {:.2} % max rel. error",
        d.base_radius(),
        d.platform_radius(),
        d.arm(),
        d.forearm(),
        o.params.k_drive,
        r.static_rel_error * 100.0
    );
    let _ = writeln!(
        t,
        "map: {} nodes ({} static tests of +-{} N), fitted per node (Eq. 10-13); move {:?} -> \
         {:?} m at {} g with {} kg payload, m* = {:.3} kg",
        r.map.node_count(),
        6 * r.map.node_count(),
        o.test_force,
        o.from,
        o.to,
        o.g,
        o.params.payload_mass,
        o.mass
    );
    let _ = writeln!(t, "run         | path max | path RMS | track max [mm]");
    for run in &r.runs {
        let _ = writeln!(
            t,
            "{:<11} | {:8.3} | {:8.3} | {:8.3}",
            if run.corrected {
                "corrected"
            } else {
                "uncorrected"
            },
            run.path_max_mm,
            run.path_rms_mm,
            run.track_max_mm
        );
    }
    if let [u, c] = r.runs.as_slice() {
        let red = |a: f64, b: f64| 100.0 * (1.0 - b / a);
        let _ = writeln!(
            t,
            "reduction: path max {:.0} %, RMS {:.0} %, tracking {:.0} %; {:.1} s wall",
            red(u.path_max_mm, c.path_max_mm),
            red(u.path_rms_mm, c.path_rms_mm),
            red(u.track_max_mm, c.track_max_mm),
            r.wall_seconds
        );
    }
    t
}
