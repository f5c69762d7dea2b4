//! Arguments of `deflect-sim job`: the offline pass over a machining program (the program, the
//! arm, the workpiece placement, the stock, the tool and material, how the program is driven),
//! each checked against its documented range before any work.

use std::path::PathBuf;

use super::range::*;
use super::{CliError, ToolArgs, count};

/// The control a G-code program is written for.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DialectArg {
    /// LinuxCNC's RS274/NGC, word for word.
    #[default]
    Linuxcnc,
    /// grbl: the off-plane centre word of an arc (K0 on a G17 arc) is ignored.
    Grbl,
    /// Fanuc, Haas, Mach3: axis words after G80 move in the last G0-G3 mode, '%' lines
    /// anywhere, nested comments.
    Fanuc,
}

impl DialectArg {
    /// The reader's dialect.
    pub fn dialect(self) -> deflect_core::io::gcode::Dialect {
        use deflect_core::io::gcode::Dialect;
        match self {
            Self::Linuxcnc => Dialect::LinuxCnc,
            Self::Grbl => Dialect::Grbl,
            Self::Fanuc => Dialect::Fanuc,
        }
    }
}

/// What `--spin` asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpinArg {
    /// The setup's orientation everywhere.
    Keep,
    /// The stiffest schedule along the program (deflect-core's `machining::spin`).
    Optimize,
    /// A constant spin \[degrees\].
    Degrees(f64),
}

impl std::str::FromStr for SpinArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "keep" => Ok(Self::Keep),
            "optimize" | "optimise" => Ok(Self::Optimize),
            other => other
                .parse::<f64>()
                .map(Self::Degrees)
                .map_err(|_| format!("{other:?}: expected keep, optimize or a spin in degrees")),
        }
    }
}

/// What the spin search minimises (`--spin-measure`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SpinMeasureArg {
    /// The deflection normal to the cut (walls and floors).
    #[default]
    Normal,
    /// The whole deflection of the tip.
    Position,
    /// Along the tool axis (floors).
    Axial,
    /// Horizontal, normal to the feed (walls).
    Lateral,
}

impl SpinMeasureArg {
    /// The core's measure.
    pub fn measure(self) -> deflect_core::machining::spin::SpinMeasure {
        use deflect_core::machining::spin::SpinMeasure;
        match self {
            Self::Normal => SpinMeasure::Normal,
            Self::Position => SpinMeasure::Position,
            Self::Axial => SpinMeasure::Axial,
            Self::Lateral => SpinMeasure::Lateral,
        }
    }
}

/// The robot controller language of `--robot-program`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum RobotProgramArg {
    /// KUKA KRL: job_program.src/.dat (LIN of E6POS with S and T), job_program_joints (PTP).
    Krl,
    /// ABB RAPID: job_program.mod (MoveL of robtargets with confdata), job_program_joints
    /// (MoveAbsJ).
    Rapid,
    /// Universal Robots URScript: job_program.script (movel), job_program_joints (servoj).
    Urscript,
    /// CSV: the commanded poses, and the joints at every sample.
    Csv,
}

impl RobotProgramArg {
    /// The writers' language.
    pub fn language(self) -> deflect_core::io::robot_program::Language {
        use deflect_core::io::robot_program::Language;
        match self {
            Self::Krl => Language::Krl,
            Self::Rapid => Language::Rapid,
            Self::Urscript => Language::UrScript,
            Self::Csv => Language::Csv,
        }
    }
}

// Arguments of `job` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug, Clone)]
pub struct JobArgs {
    /// RS274/NGC G-code program, read as LinuxCNC reads it (tools, work offsets, planes,
    /// canned cycles, parameters, subroutines, control flow; see --explain), in mm unless it
    /// says G20; its moves in the program's machine frame = the workpiece frame; or APT / CL
    /// data by its extension (.apt, .cl, .cls: GOTO with tool vectors; its CUTTER statements
    /// are the tools unless --tools is given). A program whose tool axis leaves the
    /// workpiece z runs the five-axis pass (a tri-dexel stock, the cutter's force along its
    /// edge, position and tilt compensated; the part as PLY meshes and a 3-D view). Default:
    /// data/groove_and_pocket.nc, built in (a groove, a ramp and a circular pocket in mm).
    #[arg(long, conflicts_with = "points")]
    pub program: Option<PathBuf>,
    /// Print the word report of a G-code program (every word it uses: honoured, recorded
    /// without motion, or refused; count and first line) and whether it reads, then stop.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["program", "points"])]
    pub explain: Option<PathBuf>,
    /// The control the program is written for: linuxcnc (default), grbl (ignores an arc's
    /// off-plane centre word, as FreeCAD's grbl post writes it), fanuc (Fanuc, Haas, Mach3:
    /// axis words after G80 move in the last G0-G3 mode; '%' lines anywhere; G187/G103).
    #[arg(long, value_enum, default_value_t = DialectArg::Linuxcnc)]
    pub dialect: DialectArg,
    /// Tool table: LinuxCNC's .tbl (`T1 P1 D6 Z0 ;comment`, mm; flutes and helix from
    /// --flutes/--helix, flat ends) or a TOML table (*.toml: diameter, flutes, helix, flat /
    /// ball / bull-nose). The tool in the spindle at each move cuts and feels the force.
    /// Default: the --diameter/--flutes/--helix tool serves every T.
    #[arg(long, value_name = "FILE")]
    pub tools: Option<PathBuf>,
    #[arg(long, allow_negative_numbers = true, help = SPINDLE_RPM.help(
        "Spindle speed of a program that never starts its spindle (a hand-started spindle) [rpm]",
        "It turns clockwise at this speed wherever the program's spindle is off"
    ))]
    pub spindle_rpm: Option<f64>,
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true, help = RAPID_SKIM_MM.help(
        "How deep a rapid move (G0) may run into the predicted stock before the job refuses it as a crash [mm]",
        "The deepest contact within it is in the summary"
    ))]
    pub rapid_skim: f64,
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
    /// KR 300: a table in front of it, 2.45,0.02,0.92,0,0,3.141592653589793 (for a five-axis
    /// program lower and closer, 2.0,0,0.4,0,0,3.141592653589793: the wrist stays bent as the
    /// tool tilts).
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
    #[arg(long, default_value_t = 50.0, allow_negative_numbers = true, help = STOCK_DEPTH_MM.help(
        "Five-axis programs: the stock's depth below --top [mm]", ""
    ))]
    pub stock_depth: f64,
    /// The end of the --diameter tool (five-axis programs; a tool table's or an APT CUTTER's
    /// tools carry their own): flat, ball, or bull-nose:R (corner radius R mm).
    #[arg(long, default_value = "flat", value_parser = parse_shape)]
    pub shape: ShapeArg,
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true, help = FLUTE_LENGTH_MM.help(
        "Five-axis programs: the length of every tool that removes material (flutes, and the shank that would rub) [mm]", ""
    ))]
    pub flute_length: f64,
    #[arg(long, allow_negative_numbers = true, help = CELL_MM.help(
        "Z-map cell [mm]",
        "Default: the smallest cutting tool's diameter / 12, within [0.1, 0.5] mm (at most its radius / 2, which a job requires); at most 2^24 cells (MAX_CELLS)"
    ))]
    pub cell: Option<f64>,
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
    /// Also write every sample as CSV (job_samples.csv; the .npz and the MCAP log are always
    /// written).
    #[arg(long)]
    pub samples_csv: bool,
    #[arg(long, default_value_t = 25.0, allow_negative_numbers = true, help = LOG_RATE_HZ.help(
        "Messages per second of program in the MCAP log (job.mcap) [Hz]",
        "0: every sample; the .npz has every sample"
    ))]
    pub log_rate: f64,
    #[arg(
        long,
        default_value_t = 2,
        help = "Threads: 1 runs the pass on one; 2 or more run \
        its two predictions side by side (the results do not depend on it) [1..=64]"
    )]
    pub threads: usize,
    #[arg(long, default_value_t = 0.001, allow_negative_numbers = true, help = TOLERANCE_MM.help(
        "Largest distance of the compensated G-code from the commanded path [mm]", ""
    ))]
    pub tolerance: f64,
    /// Also write the compensated job as the robot controller's own program, both commands
    /// (Cartesian: job_program.*, axis-specific: job_program_joints.*), decimated to
    /// --tolerance; KRL, RAPID and URScript need the robot's [controller] convention (the
    /// built-in KR 300 has KUKA's).
    #[arg(long, value_enum)]
    pub robot_program: Option<RobotProgramArg>,
    /// The tool's spin about its own axis: keep (the setup's orientation), optimize (the
    /// schedule of least predicted deflection along the program, within the joint limits, a
    /// singularity margin and --spin-rate), or a constant spin in degrees.
    #[arg(long, default_value = "keep", allow_negative_numbers = true)]
    pub spin: SpinArg,
    #[arg(long, default_value_t = 5.0, help = SPIN_STEP_DEG.help(
        "Spacing of the spin search's candidates [degrees]", "Candidates within +-180 degrees"
    ))]
    pub spin_step: f64,
    /// The spin's rate bounds: DEG_PER_MM,DEG_PER_S (of path and of time) [1,30].
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 30.0])]
    pub spin_rate: Vec<f64>,
    /// What the spin search minimises.
    #[arg(long, value_enum, default_value_t = SpinMeasureArg::Normal)]
    pub spin_measure: SpinMeasureArg,
}

/// `--shape`: a cutter's end; a bull-nose's corner radius in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeArg(pub deflect_core::machining::profile::ToolShape);

/// `flat`, `ball` or `bull-nose:R` (R in mm, > 0).
pub fn parse_shape(s: &str) -> Result<ShapeArg, String> {
    use deflect_core::machining::profile::ToolShape;
    match s.trim().to_ascii_lowercase().as_str() {
        "flat" => Ok(ShapeArg(ToolShape::Flat)),
        "ball" => Ok(ShapeArg(ToolShape::Ball)),
        other => {
            let r = other
                .strip_prefix("bull-nose:")
                .and_then(|r| r.parse::<f64>().ok())
                .filter(|r| r.is_finite() && *r > 0.0)
                .ok_or_else(|| {
                    format!("{s:?}: expected flat, ball or bull-nose:R (corner radius R > 0 mm)")
                })?;
            Ok(ShapeArg(ToolShape::BullNose {
                corner_radius: r * 1e-3,
            }))
        }
    }
}

impl JobArgs {
    /// Checks every numeric flag and the lengths of the lists.
    pub fn check(&self) -> Result<(), CliError> {
        TOP_MM.check(self.top)?;
        STOCK_DEPTH_MM.check(self.stock_depth)?;
        FLUTE_LENGTH_MM.check(self.flute_length)?;
        if let Some(cell) = self.cell {
            CELL_MM.check(cell)?;
        }
        LOG_RATE_HZ.check(self.log_rate)?;
        if !(1..=64).contains(&self.threads) {
            return Err(CliError::Usage(format!(
                "--threads {}: expected 1..=64",
                self.threads
            )));
        }
        self.tool.check()?;
        RATE_HZ.check(self.rate)?;
        PATH_ACCELERATION.check(self.acceleration)?;
        PATH_JERK.check(self.jerk)?;
        RAPID_SPEED.check(self.rapid_speed)?;
        LEAD_MS.check(self.lead_ms)?;
        TOLERANCE_MM.check(self.tolerance)?;
        if let SpinArg::Degrees(d) = self.spin {
            SPIN_DEG.check(d)?;
        }
        SPIN_STEP_DEG.check(self.spin_step)?;
        match self.spin_rate.as_slice() {
            [per_mm, per_s] => {
                SPIN_RATE_PER_MM.check(*per_mm)?;
                SPIN_RATE_PER_S.check(*per_s)?;
            }
            v => {
                return Err(CliError::Usage(format!(
                    "--spin-rate: {} values; expected 2 (degrees per mm, degrees per second)",
                    v.len()
                )));
            }
        }
        RAPID_SKIM_MM.check(self.rapid_skim)?;
        if let Some(rpm) = self.spindle_rpm {
            SPINDLE_RPM.check(rpm)?;
        }
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
        if let Some(p) = &self.placement
            && let [x, y, z, angles @ ..] = p.as_slice()
        {
            let far = [x, y, z].into_iter().find(|v| v.abs() > 1.0e3);
            let turned = angles.iter().find(|a| a.abs() > std::f64::consts::TAU);
            if let Some(v) = far {
                return Err(CliError::Usage(format!(
                    "--placement: {v:e} m; expected x,y,z within +-1000 m"
                )));
            }
            if let Some(a) = turned {
                return Err(CliError::Usage(format!(
                    "--placement: {a:e} rad; expected roll,pitch,yaw within +-2 pi rad (radians, \
                     not degrees)"
                )));
            }
        }
        if let Some(seed) = &self.seed
            && let Some(v) = seed
                .iter()
                .find(|v| !(v.is_finite() && v.abs() <= deflect_core::vjm::MAX_JOINT_POSITION))
        {
            return Err(CliError::Usage(format!(
                "--seed: {v}; expected finite joint values (rad or m) within +-1e6"
            )));
        }
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
