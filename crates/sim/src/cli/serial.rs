//! Arguments of `deflect-sim serial`: the arm (URDF, stiffness, tip), payload, motion,
//! corrector and servo, each checked against its documented range.

use std::path::PathBuf;

use clap::ValueEnum;

use super::range::*;
use super::{CliError, count};

// Arguments of `serial` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct SerialArgs {
    /// Robot URDF (a regular file of at most 16 MiB, with <inertial> for the links' masses);
    /// default: the KR 300 R2500 built into deflect-sim. Needs --stiffness.
    #[arg(long, requires = "stiffness")]
    pub urdf: Option<PathBuf>,
    /// Stiffness TOML of the virtual joints (deflect's format, see robots/); default: the
    /// KR 300's.
    #[arg(long)]
    pub stiffness: Option<PathBuf>,
    /// Base link of the chain (default: the URDF's root).
    #[arg(long)]
    pub base: Option<String>,
    /// Tip (TCP) link of the chain; default: "tcp" for the KR 300, else the URDF's deepest
    /// leaf link (an error if two leaves are equally deep).
    #[arg(long)]
    pub tip: Option<String>,
    /// Start joints [rad], comma-separated, one per actuated joint; default: the KR 300's
    /// milling pose, else the most dexterous pose of the grid {-1, -0.5, 0, 0.5, 1}^n rad
    /// inside the joint limits (largest smallest singular value of the Jacobian).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub q0: Option<Vec<f64>>,
    #[arg(long, allow_negative_numbers = true, help = PAYLOAD_MASS.help(
        "Payload and tool mass [kg], a cube of aluminium (2700 kg/m^3) centred on the tool \
         axis half a side beyond the flange",
        "Default: 150 kg on the KR 300, else 10 % of the URDF's link masses"
    ))]
    pub payload_mass: Option<f64>,
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true, help = SERIAL_G.help("Peak acceleration [g]", ""))]
    pub g: f64,
    #[arg(long, allow_negative_numbers = true, help = SCALE.help(
        "Size of the motions [m]: line (0.3, 0.2, -0.1) x scale, circle radius 0.15 x scale",
        "Default: 1 on the KR 300, else a third of the TCP's distance from the base at zero joints"
    ))]
    pub scale: Option<f64>,
    #[arg(long, allow_negative_numbers = true, help = V_MAX.help("Largest speed [m/s]", "Default: 2 x scale per second"))]
    pub v_max: Option<f64>,
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true, help = RAMP.help(
        "Time to ramp the acceleration up [s] (sets the jerk)",
        ""
    ))]
    pub ramp: f64,
    #[arg(long, default_value_t = 0.3, allow_negative_numbers = true, help = TURN.help(
        "Turn of the tool about the vertical over each motion [rad]",
        ""
    ))]
    pub turn: f64,
    /// Correct the payload's inertial wrench only (the paper's D'Alembert force); by default
    /// the links' own inertial loads are corrected as well when the URDF has masses.
    #[arg(long)]
    pub payload_only: bool,
    /// Deflection model the corrector inverts.
    #[arg(long, value_enum, default_value_t = ModelArg::Exact)]
    pub model: ModelArg,
    /// What the IK controls; auto: the largest of pose, position-and-axis, position-and-spin,
    /// position that has no more rows than the arm has joints and is not singular at the
    /// start joints (the pose on a 6-axis arm).
    #[arg(long, value_enum, default_value_t = TaskArg::Auto)]
    pub task: TaskArg,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads (one run each; results do not depend on it)",
        "0 is refused"
    ))]
    pub jobs: usize,
}

// What the serial corrector's IK controls.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum TaskArg {
    // The largest task the arm controls at the start joints.
    Auto,
    // Position and orientation (6 or more joints).
    Pose,
    // Position and the tool axis; the spin about it is free (5 or more joints).
    PositionAndAxis,
    // Position and the spin about the tool axis (a SCARA; 4 or more joints).
    PositionAndSpin,
    // Position only.
    Position,
}

// Deflection model of the serial corrector.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum ModelArg {
    // Virtual-joint deflection, Eq. 2-9 of Hahn and Weigold.
    Exact,
    // The linearized compliance J K^-1 J^T.
    Linearized,
}

impl SerialArgs {
    /// See [`Command::check`]; the files are checked and loaded by the scenario's `load`.
    pub fn check(&self) -> Result<(), CliError> {
        if let Some(m) = self.payload_mass {
            PAYLOAD_MASS.check(m)?;
        }
        SERIAL_G.check(self.g)?;
        if let Some(v) = self.scale {
            SCALE.check(v)?;
        }
        if let Some(v) = self.v_max {
            V_MAX.check(v)?;
        }
        RAMP.check(self.ramp)?;
        TURN.check(self.turn)?;
        if let Some(q) = &self.q0
            && let Some((i, v)) = q.iter().enumerate().find(|(_, v)| !v.is_finite())
        {
            return Err(CliError::Usage(format!(
                "--q0: joint {i} is {v}: expected a finite angle [rad]"
            )));
        }
        JOBS.check_int(count(self.jobs))
    }
}
