//! Arguments of `deflect-sim atlas` and the parsing of its `--region`.

use std::path::PathBuf;

use super::{ANGLE_STEP, ATLAS_POINTS, CliError, JOBS, count};

// Arguments of `atlas` (help texts with their ranges in the `help` attributes).
#[derive(clap::Args, Debug)]
pub struct AtlasArgs {
    /// Robot URDF (a regular file of at most 16 MiB); default: the KR 300 R2500 built into
    /// deflect-sim. Needs --stiffness.
    #[arg(long, requires = "stiffness")]
    pub urdf: Option<PathBuf>,
    /// Stiffness TOML of the virtual joints; default: the KR 300's.
    #[arg(long, requires = "urdf")]
    pub stiffness: Option<PathBuf>,
    /// Base link of the chain (default: the URDF's root).
    #[arg(long)]
    pub base: Option<String>,
    /// Tip (TCP) link; default "tcp" for the KR 300, else the URDF's deepest leaf link.
    #[arg(long)]
    pub tip: Option<String>,
    #[arg(long, default_value = "1.4:2.2:9,-0.6:0.6:7,0.2", help = ATLAS_POINTS.help(
        "Grid on a horizontal plane, base frame [m]: X0:X1:NX,Y0:Y1:NY,Z (NX, NY points per axis)",
        "Coordinates within 1000 m"
    ))]
    pub region: String,
    /// Tool axis (the TCP z axis), base frame, comma-separated, any non-zero length.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        default_value = "0,0,-1"
    )]
    pub tool_axis: Vec<f64>,
    /// Process wrench at the TCP [N, N m], base frame: Fx,Fy,Fz,Mx,My,Mz; default the 546 N
    /// milling force of Hähn and Weigold (sec. 3).
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        default_value = "-386.1,386.1,0,0,0,0"
    )]
    pub wrench: Vec<f64>,
    #[arg(long, default_value_t = 5.0, help = ANGLE_STEP.help(
        "Step of the sweep about the tool axis over the full turn [deg]",
        "The best angle is refined between its neighbours"
    ))]
    pub angle_step: f64,
    /// IK seed [rad], comma-separated, one per joint: a posture near the work; default the
    /// KR 300's milling pose, else the middle of the joint limits.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub seed: Option<Vec<f64>>,
    #[arg(long, default_value_t = 2, help = JOBS.help(
        "Worker threads (one grid row each; results do not depend on it)",
        "0 is refused"
    ))]
    pub jobs: usize,
}

/// A grid axis: `from`, `to` [m] and the number of points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridAxis {
    /// First coordinate [m].
    pub from: f64,
    /// Last coordinate [m].
    pub to: f64,
    /// Points (1: `from` only).
    pub n: usize,
}

impl GridAxis {
    /// The coordinates.
    pub fn points(&self) -> Vec<f64> {
        if self.n <= 1 {
            return vec![self.from];
        }
        let step = (self.to - self.from) / (self.n - 1) as f64;
        (0..self.n).map(|k| self.from + step * k as f64).collect()
    }
}

impl AtlasArgs {
    /// `--region` as the x axis, the y axis and the height; a usage error naming the flag.
    pub fn region(&self) -> Result<(GridAxis, GridAxis, f64), CliError> {
        let bad = |why: &str| {
            CliError::Usage(format!(
                "--region {}: {why}; expected X0:X1:NX,Y0:Y1:NY,Z in m with NX, NY in {}",
                self.region,
                ATLAS_POINTS.text()
            ))
        };
        let parts: Vec<&str> = self.region.split(',').collect();
        let [xs, ys, z] = parts.as_slice() else {
            return Err(bad("not three comma-separated parts"));
        };
        let number = |t: &str| -> Result<f64, CliError> {
            let v: f64 = t
                .trim()
                .parse()
                .map_err(|_| bad(&format!("'{t}' is not a number")))?;
            if v.is_finite() && v.abs() <= 1000.0 {
                Ok(v)
            } else {
                Err(bad(&format!("{v} is not a coordinate within 1000 m")))
            }
        };
        let axis = |t: &str| -> Result<GridAxis, CliError> {
            let f: Vec<&str> = t.split(':').collect();
            let [a, b, n] = f.as_slice() else {
                return Err(bad(&format!("'{t}' is not FROM:TO:N")));
            };
            let n: usize = n
                .trim()
                .parse()
                .map_err(|_| bad(&format!("'{n}' is not a count of points")))?;
            if !ATLAS_POINTS.contains(n as f64) {
                return Err(bad(&format!("{n} points on an axis")));
            }
            Ok(GridAxis {
                from: number(a)?,
                to: number(b)?,
                n,
            })
        };
        Ok((axis(xs)?, axis(ys)?, number(z)?))
    }

    /// See [`Command::check`]; the robot files and the seed's length are checked by the
    /// scenario's `load`.
    pub fn check(&self) -> Result<(), CliError> {
        self.region()?;
        ANGLE_STEP.check(self.angle_step)?;
        let finite = |flag: &str, v: &[f64], n: usize, what: &str| -> Result<(), CliError> {
            if v.len() != n || v.iter().any(|x| !x.is_finite()) {
                return Err(CliError::Usage(format!(
                    "{flag}: {} values {v:?}; expected {n} finite {what}",
                    v.len()
                )));
            }
            Ok(())
        };
        finite("--tool-axis", &self.tool_axis, 3, "components")?;
        if self.tool_axis.iter().all(|v| *v == 0.0) {
            return Err(CliError::Usage(
                "--tool-axis 0,0,0: expected a non-zero direction".into(),
            ));
        }
        finite("--wrench", &self.wrench, 6, "components [N, N m]")?;
        if let Some(q) = &self.seed
            && let Some((i, v)) = q.iter().enumerate().find(|(_, v)| !v.is_finite())
        {
            return Err(CliError::Usage(format!(
                "--seed: joint {i} is {v}: expected a finite angle [rad]"
            )));
        }
        JOBS.check_int(count(self.jobs))
    }
}
