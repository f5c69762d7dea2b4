//! `milling`: the hybrid compensation of Hähn and Weigold (sec. 2.2-2.6, 3). By default the
//! paper's validation: deflect's test workpiece (or `--program`) cut by the flexible KR 300
//! five ways ([`deflect_sim::scenes::milling::program`]); `--program groove` runs the straight
//! groove with a prescribed force step ([`deflect_sim::scenes::milling::run`]) with the
//! command line's feed, force, timing and noise settings. Prints the summary table and writes
//! its files.

use std::path::Path;

use deflect_core::machining::five_axis::Options;
use deflect_sim::SimError;
use deflect_sim::scenes::milling::program;
use deflect_sim::scenes::milling::program_output;
use deflect_sim::scenes::milling::{self, output, part_map};

use super::Cmd;
use crate::cli::{CliError, MillingArgs};

mod five_axis;
mod input;

use input::ProgramInput;
pub use input::{MillingInput, load};

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
    opts.program_dt = a.step_ms * 1e-3;
    opts.program_substeps = a.substeps;
    opts.spindle_mass = a.spindle_mass;
    opts.link_inertia = !a.no_link_inertia;
    opts.jobs = a.jobs;
    opts
}

/// The `milling` command (arguments checked by [`MillingArgs::check`], inputs by [`load`]).
fn run(a: &MillingArgs, input: &MillingInput, out: &Path) -> Result<(), SimError> {
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
    let ProgramInput {
        program,
        name,
        setup,
        q0,
        arm,
        tools,
        shape,
    } = p.as_ref();
    // An arm of the user's is identified at its start joints (the KR 300 at the paper's
    // milling pose, as in the groove scenario).
    let opts = if a.urdf.is_none() {
        opts
    } else {
        milling::MillingOptions {
            q0: q0.clone(),
            ..opts
        }
    };
    if program.is_multi_axis() {
        let options = Options {
            shape: *shape,
            ..Options::default()
        };
        return five_axis::run_and_write(&opts, p.as_ref(), tools.as_ref(), &options, out);
    }
    let r = program::milling_program(&opts, arm, program, setup, q0)?;
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
            &format!(
                "{name}, {} in rapier: the part's height above the nominal one",
                r.robot
            ),
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

impl Cmd for MillingArgs {
    type Input = MillingInput;

    fn load(&self) -> Result<MillingInput, CliError> {
        load(self)
    }

    fn run(&self, input: MillingInput, out: &Path) -> Result<(), SimError> {
        run(self, &input, out)
    }
}
