//! `milling`: the online force-based compensation of Hähn and Weigold (sec. 2.2-2.6, 3) in
//! the milling scenario of [`deflect_sim::scenes::milling`], with the command line's feed, force,
//! timing and noise settings; prints the summary table and writes its files.

use std::path::Path;

use deflect_sim::SimError;
use deflect_sim::scenes::milling::{self, output};

use crate::cli::MillingArgs;

/// The `milling` command (arguments checked by [`MillingArgs::check`]).
pub fn milling_cmd(a: &MillingArgs, out: &Path) -> Result<(), SimError> {
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
    let r = milling::milling(&opts)?;
    let table = output::table(&r);
    put!("{table}");
    output::write_all(out, &r)?;
    say!(
        "wrote {}/milling_summary.{{txt,csv,json}}, milling.mcap, milling_error.png, milling_stiffness.png",
        out.display()
    );
    Ok(())
}
