//! Arguments of `deflect-sim place`: a machining job's arguments (`job`'s, the program, the
//! arm and the tool) and the box the workpiece placement is searched in.

use super::CliError;
use super::job::JobArgs;

/// `place`: where to put the workpiece for the least predicted deflection.
#[derive(clap::Args, Debug)]
pub struct PlaceArgs {
    #[command(flatten)]
    pub job: JobArgs,
    /// The box of the workpiece origin in the base frame: X0,X1,Y0,Y1,Z0,Z1 [m] (default: the
    /// job's placement +-0.2 m in x and y, +-0.1 m in z).
    #[arg(long = "box", value_delimiter = ',', allow_hyphen_values = true)]
    pub bounds: Option<Vec<f64>>,
    /// The turn about the vertical of the job's placement: YAW0,YAW1 [degrees].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, default_values_t = [-30.0, 30.0])]
    pub yaw: Vec<f64>,
    /// Grid points per axis: NX,NY,NZ,NYAW (1: the axis' middle) [1..=1024, at most 2^20 in all].
    #[arg(long, value_delimiter = ',', default_values_t = [7, 7, 3, 3])]
    pub steps: Vec<usize>,
    /// Rounds of the compass refinement around the grid's best point (half the spacing each)
    /// [0..=30].
    #[arg(long, default_value_t = 3)]
    pub refine: usize,
}

impl PlaceArgs {
    /// Checks the job's arguments and the box's.
    pub fn check(&self) -> Result<(), CliError> {
        self.job.check()?;
        if let Some(b) = &self.bounds {
            if b.len() != 6 || b.iter().any(|v| !v.is_finite() || v.abs() > 1.0e3) {
                return Err(CliError::Usage(format!(
                    "--box {b:?}: expected X0,X1,Y0,Y1,Z0,Z1, finite, within +-1000 m"
                )));
            }
            for (axis, pair) in ["x", "y", "z"].iter().zip(b.chunks(2)) {
                if let [lo, hi] = pair
                    && lo > hi
                {
                    return Err(CliError::Usage(format!(
                        "--box: {axis} from {lo} to {hi}; expected the lower end first"
                    )));
                }
            }
        }
        match self.yaw.as_slice() {
            [lo, hi]
                if lo.is_finite()
                    && hi.is_finite()
                    && lo <= hi
                    && lo.abs() <= 360.0
                    && hi.abs() <= 360.0 => {}
            v => {
                return Err(CliError::Usage(format!(
                    "--yaw {v:?}: expected YAW0,YAW1 [degrees], YAW0 <= YAW1, within +-360"
                )));
            }
        }
        if self.steps.len() != 4 || self.steps.iter().any(|s| !(1..=1024).contains(s)) {
            return Err(CliError::Usage(format!(
                "--steps {:?}: expected NX,NY,NZ,NYAW, each 1..=1024",
                self.steps
            )));
        }
        if self.steps.iter().product::<usize>() > deflect_core::machining::placement::MAX_GRID {
            return Err(CliError::Usage(format!(
                "--steps {:?}: {} placements; at most 2^20 (MAX_GRID)",
                self.steps,
                self.steps.iter().product::<usize>()
            )));
        }
        if self.refine > deflect_core::machining::placement::MAX_REFINE {
            return Err(CliError::Usage(format!(
                "--refine {}: expected 0..=30",
                self.refine
            )));
        }
        if self.job.explain.is_some() {
            return Err(CliError::Usage(
                "--explain: a job's flag, not place's".into(),
            ));
        }
        Ok(())
    }
}
