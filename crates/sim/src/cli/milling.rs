//! Arguments of `deflect-sim milling`.

use deflect_sim::scenes::parallel::params;

use deflect_core::machining::path::{Blending, MAX_BLEND_TOLERANCE};
use std::path::PathBuf;

use super::range::*;
use super::{CliError, ToolArgs, count};

// Arguments of `milling` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct MillingArgs {
    /// Machining program cut by the flexible arm (G-code in the workpiece frame, mm per
    /// G21; APT / CL data by the extension .apt, .cl or .cls; a program whose tool axis leaves
    /// the workpiece z runs the uncompensated and offline compensated joints of the five-axis
    /// pass, the force read where the simulated tool is and as it is tilted), or `groove` for the straight groove with a prescribed force step (the scenario
    /// before programs, which uses --feed, --force, --cut, --rise-ms and --estimate-error);
    /// default: deflect's test workpiece (data/test_workpiece.nc, built in).
    #[arg(long)]
    pub program: Option<String>,
    /// Stock XMIN,YMIN,XMAX,YMAX [mm], workpiece frame; default: 0,0,140,130 for the test
    /// workpiece, else the feed moves' bounding box grown by the tool radius.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub stock: Option<Vec<f64>>,
    /// Robot URDF (a regular file of at most 16 MiB) for programs; default: the KR 300 R2500
    /// built into deflect-sim. Needs --stiffness, --placement and --q0. The force/torque
    /// sensor is at a link named ft_sensor if the URDF has one, else at the TCP.
    #[arg(long, requires_all = ["stiffness", "placement", "q0"])]
    pub urdf: Option<PathBuf>,
    /// Stiffness TOML of the virtual joints (deflect's format); default: the KR 300's.
    #[arg(long, requires = "urdf")]
    pub stiffness: Option<PathBuf>,
    /// Base link of the chain (default: the URDF's root).
    #[arg(long, requires = "urdf")]
    pub base: Option<String>,
    /// Tip link: the tool tip; default "tcp" for the KR 300, else the URDF's deepest leaf.
    #[arg(long, requires = "urdf")]
    pub tip: Option<String>,
    /// The workpiece frame in the arm's base frame: x,y,z [m], roll,pitch,yaw [rad] (the tool
    /// points down its z); default for the KR 300: a table in front of it,
    /// 2.52,0.07,0.92,0,0,3.141592653589793.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub placement: Option<Vec<f64>>,
    /// Joints near the program's first pose [rad], one per joint (they choose the IK branch;
    /// the stiffness identification's first pose with --urdf); default for the KR 300
    /// 0,-0.9,1.4,0,-0.5,0 (the tool down over the table).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub q0: Option<Vec<f64>>,
    #[command(flatten)]
    pub tool: ToolArgs,
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true, help = CELL_MM.help(
        "Z-map cell of the stock [mm]", "At most 2^24 cells (MAX_CELLS)"
    ))]
    pub cell: f64,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads (one run each; results do not depend on it)",
        "0 is refused"
    ))]
    pub jobs: usize,
    #[arg(long, default_value_t = 25.0, help = FEED.help("Feed speed [mm/s] (paper: 25)", ""))]
    pub feed: f64,
    #[arg(long, default_value_t = 550.0, allow_negative_numbers = true, help = FORCE.help(
        "Magnitude of the process force [N] (direction as the default [-386, 386, -60] N)",
        ""
    ))]
    pub force: f64,
    #[arg(long, default_value_t = 1.2, help = CUT.help("Cutting time [s]", ""))]
    pub cut: f64,
    #[arg(long, default_value_t = 100.0, help = RISE_MS.help(
        "Rise and fall time of the force at cutter entry and exit [ms]",
        ""
    ))]
    pub rise_ms: f64,
    #[arg(long, default_value_t = 4.0, help = CYCLE_MS.help(
        "Control cycle [ms] (paper: 4, KUKA RSI)",
        "A multiple of the 0.5 ms physics step"
    ))]
    pub cycle_ms: f64,
    #[arg(long, default_value_t = 40.0, help = LEAD_MS.help(
        "Lead of the offline force estimate over the real force [ms]",
        ""
    ))]
    pub lead_ms: f64,
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true, help = ESTIMATE_ERROR.help(
        "Relative error of the offline force estimate (0.1 = 10 % too large)",
        "Negative values: an estimate too small"
    ))]
    pub estimate_error: f64,
    /// Seed of the sensor and measurement noise.
    #[arg(long, default_value_t = 6, allow_negative_numbers = true)]
    pub seed: u64,
    #[arg(long, default_value_t = 3, allow_negative_numbers = true, help = ID_POSES.help(
        "Poses of the stiffness identification's static tests (each about 3.4 s simulated)",
        "Fewer poses: a faster run, fewer identifiable axes"
    ))]
    pub id_poses: usize,
    #[arg(long, default_value_t = 1.0, help = PHYSICS_STEP_MS.help(
        "Largest physics step of the program runs [ms] (shortened to divide the control cycle)",
        "The step-size check: 0.5 against the default 1"
    ))]
    pub step_ms: f64,
    #[arg(long, default_value_t = 2, help = SUBSTEPS.help(
        "rapier substeps per physics step of the program scenarios (rapier's default: 4)",
        "Each substep rebuilds the arm's mass matrix, most of a run's time"
    ))]
    pub substeps: usize,
    #[arg(long, default_value_t = 0.0, help = SPINDLE_MASS.help(
        "Mass of the spindle and tool beyond the TCP [kg] in programs (a point halfway to the sensor): the simulated arm carries it, the combined run's inertial feed-forward counts it",
        "0: the built-in KR 300's massless spindle"
    ))]
    pub spindle_mass: f64,
    /// Leave the link masses' loads out of the combined run's inertial feed-forward (with
    /// --spindle-mass 0 the combined run is then the hybrid one).
    #[arg(long)]
    pub no_link_inertia: bool,
    /// How a program's corners are driven: `stop` (an exact stop at each, the tool on the
    /// programmed geometry), `program` (the program's G64 P tolerance, G61 / G61.1 stop) or a
    /// tolerance [mm] in [0, 100] for every corner (0: as fast as the ramps allow); a
    /// tolerance past both moves at a corner is refused.
    #[arg(long, default_value = "stop")]
    pub blend: String,
}

impl MillingArgs {
    /// See [`Command::check`]; the control cycle is also a whole number of physics steps.
    pub fn check(&self) -> Result<(), CliError> {
        FEED.check(self.feed)?;
        FORCE.check(self.force)?;
        CUT.check(self.cut)?;
        RISE_MS.check(self.rise_ms)?;
        CYCLE_MS.check(self.cycle_ms)?;
        let dt_ms = params::DT * 1e3;
        let steps = self.cycle_ms / dt_ms;
        if (steps - steps.round()).abs() > 1e-9 {
            return Err(CliError::Usage(format!(
                "--cycle-ms {} is not a multiple of the {dt_ms} ms physics step: allowed {}, \
                 in steps of {dt_ms} ms",
                shown(self.cycle_ms),
                CYCLE_MS.text()
            )));
        }
        LEAD_MS.check(self.lead_ms)?;
        ESTIMATE_ERROR.check(self.estimate_error)?;
        CELL_MM.check(self.cell)?;
        JOBS.check_int(count(self.jobs))?;
        let list = |flag: &str, v: &Option<Vec<f64>>, n: usize, what: &str| match v {
            Some(v) if v.len() != n || v.iter().any(|x| !x.is_finite()) => Err(CliError::Usage(
                format!("{flag}: {v:?}; expected {n} finite values ({what})"),
            )),
            _ => Ok(()),
        };
        list("--stock", &self.stock, 4, "XMIN,YMIN,XMAX,YMAX [mm]")?;
        list(
            "--placement",
            &self.placement,
            6,
            "x,y,z [m], roll,pitch,yaw [rad]",
        )?;
        if let Some(q) = &self.q0
            && q.iter().any(|x| !x.is_finite())
        {
            return Err(CliError::Usage(format!(
                "--q0: {q:?}; expected finite joint angles [rad]"
            )));
        }
        self.tool.check()?;
        PHYSICS_STEP_MS.check(self.step_ms)?;
        SUBSTEPS.check_int(count(self.substeps))?;
        SPINDLE_MASS.check(self.spindle_mass)?;
        self.blending()?;
        ID_POSES.check_int(count(self.id_poses))
    }

    /// `--blend` as the path's blending (the tolerance in metres).
    pub fn blending(&self) -> Result<Blending, CliError> {
        match self.blend.as_str() {
            "stop" => Ok(Blending::ExactStop),
            "program" => Ok(Blending::Program),
            mm => match mm.parse::<f64>() {
                Ok(v) if (0.0..=MAX_BLEND_TOLERANCE * 1e3).contains(&v) => {
                    Ok(Blending::Tolerance(v * 1e-3))
                }
                _ => Err(CliError::Usage(format!(
                    "--blend {mm}: expected stop, program or a tolerance in [0, 100] mm"
                ))),
            },
        }
    }
}
