//! Arguments of `deflect-sim job`: the offline pass over a machining program (the program, the
//! arm, the workpiece placement, the stock, the tool and material, how the program is driven),
//! each checked against its documented range before any work.

use std::path::PathBuf;

use super::range::*;
use super::{CliError, ToolArgs, count};

// Arguments of `job` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct JobArgs {
    /// G-code program (ISO subset: G0-G3 in G17, G20/G21, G90/G91, F, S, M3/M5/M30), in the
    /// workpiece frame; default: data/groove_and_pocket.nc, built in (a groove, a ramp and a
    /// circular pocket in mm).
    #[arg(long, conflicts_with = "points")]
    pub program: Option<PathBuf>,
    /// Tool points CSV instead of G-code (columns x_mm,y_mm,z_mm or x_m,y_m,z_m,
    /// feed_mm_min or feed_m_s, spindle_rpm; one straight move per row, feed 0 for rapid).
    #[arg(long)]
    pub points: Option<PathBuf>,
    /// Robot URDF (a regular file of at most 16 MiB); default: the KR 300 R2500 built into
    /// deflect-sim. Needs --stiffness, --placement and --seed.
    #[arg(long, requires_all = ["stiffness", "placement", "seed"])]
    pub urdf: Option<PathBuf>,
    /// Stiffness TOML of the virtual joints; default: the KR 300's.
    #[arg(long, requires = "urdf")]
    pub stiffness: Option<PathBuf>,
    /// Base link of the chain (default: the URDF's root).
    #[arg(long)]
    pub base: Option<String>,
    /// Tip link: the tool tip; default "tcp" for the KR 300, else the URDF's deepest leaf.
    #[arg(long)]
    pub tip: Option<String>,
    /// Joints near the program's first pose [rad], comma-separated (they choose the IK
    /// branch); default for the KR 300: 0,-0.9,1.4,0,-0.5,0 (the tool down over the table).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub seed: Option<Vec<f64>>,
    /// The workpiece frame in the robot's base frame: x,y,z [m], roll,pitch,yaw [rad] (URDF
    /// convention, Rz(yaw) Ry(pitch) Rx(roll)); the tool points down its z. Default for the
    /// KR 300: a table in front of it, 2.45,0.02,0.92,0,0,3.141592653589793.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub placement: Option<Vec<f64>>,
    /// Stock block in the workpiece frame: XMIN,YMIN,XMAX,YMAX [mm]; default: the bounding
    /// box of the feed moves grown by the tool radius.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub stock: Option<Vec<f64>>,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, help = TOP_MM.help(
        "Stock top in the workpiece frame [mm]", "CAM's usual zero"
    ))]
    pub top: f64,
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true, help = CELL_MM.help(
        "Z-map cell [mm]", "At most 2^24 cells (MAX_CELLS)"
    ))]
    pub cell: f64,
    #[command(flatten)]
    pub tool: ToolArgs,
    #[arg(long, default_value_t = 250.0, allow_negative_numbers = true, help = RATE_HZ.help(
        "Sampling rate of the program [Hz]", "Default: the 4 ms RSI cycle of the paper"
    ))]
    pub rate: f64,
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true, help = PATH_ACCELERATION.help(
        "Path acceleration limit [m/s^2]", ""
    ))]
    pub acceleration: f64,
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true, help = PATH_JERK.help(
        "Path jerk limit [m/s^3]", ""
    ))]
    pub jerk: f64,
    #[arg(long, default_value_t = 0.25, allow_negative_numbers = true, help = RAPID_SPEED.help(
        "Speed of rapid moves [m/s]", ""
    ))]
    pub rapid_speed: f64,
    #[arg(long, default_value_t = 40.0, allow_negative_numbers = true, help = LEAD_MS.help(
        "Lead of the pilot-control forces in the samples CSV [ms]", "The paper used 40 ms"
    ))]
    pub lead_ms: f64,
    #[arg(long, default_value_t = 0.001, allow_negative_numbers = true, help = TOLERANCE_MM.help(
        "Largest distance of the compensated G-code from the commanded path [mm]", ""
    ))]
    pub tolerance: f64,
}

impl JobArgs {
    /// Checks every numeric flag and the lengths of the lists.
    pub fn check(&self) -> Result<(), CliError> {
        TOP_MM.check(self.top)?;
        CELL_MM.check(self.cell)?;
        self.tool.check()?;
        RATE_HZ.check(self.rate)?;
        PATH_ACCELERATION.check(self.acceleration)?;
        PATH_JERK.check(self.jerk)?;
        RAPID_SPEED.check(self.rapid_speed)?;
        LEAD_MS.check(self.lead_ms)?;
        TOLERANCE_MM.check(self.tolerance)?;
        let list = |flag: &str, v: &Option<Vec<f64>>, n: usize, what: &str| match v {
            Some(v) if v.len() != n => Err(CliError::Usage(format!(
                "{flag}: {} values; expected {n} ({what})",
                count(v.len())
            ))),
            Some(v) if v.iter().any(|x| !x.is_finite()) => Err(CliError::Usage(format!(
                "{flag}: {v:?} has a value that is not finite; expected {what}"
            ))),
            _ => Ok(()),
        };
        list(
            "--placement",
            &self.placement,
            6,
            "x,y,z [m], roll,pitch,yaw [rad]",
        )?;
        list("--stock", &self.stock, 4, "XMIN,YMIN,XMAX,YMAX [mm]")?;
        if let Some(s) = &self.stock
            && let [x0, y0, x1, y1] = s.as_slice()
            && !(x1 > x0 && y1 > y0)
        {
            return Err(CliError::Usage(format!(
                "--stock {x0},{y0},{x1},{y1}: expected XMIN < XMAX and YMIN < YMAX [mm]"
            )));
        }
        Ok(())
    }
}
