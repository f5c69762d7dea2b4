//! The cutter and the material, shared by `job` and `milling`: the same flags, ranges and
//! defaults (the paper's 16 mm three-flute end mill; Al7075-T6 standing in for AW2017).

use super::CliError;
use super::range::*;

/// Tool and material flags (flattened into `job` and `milling`).
#[derive(clap::Args, Debug, Clone)]
pub struct ToolArgs {
    #[arg(long, default_value_t = 16.0, allow_negative_numbers = true, help = DIAMETER_MM.help(
        "Flat end mill diameter [mm]", "Default: the 16 mm tool of Hähn and Weigold"
    ))]
    pub diameter: f64,
    #[arg(long, default_value_t = 3, allow_negative_numbers = true, help = FLUTES.help("Flutes", ""))]
    pub flutes: u32,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, help = HELIX_DEG.help(
        "Helix angle [deg]", "The per-revolution force does not depend on it"
    ))]
    pub helix: f64,
    /// Cutting and edge coefficients of the material (alias --material):
    /// k_tc,k_rc,k_ac [N/mm^2], k_te,k_re,k_ae [N/mm]; default Al7075-T6 with a carbide tool
    /// (Zhang et al. 2021, Table 5), a stand-in for the paper's AW2017.
    #[arg(
        long,
        visible_alias = "material",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub coefficients: Option<Vec<f64>>,
}

impl ToolArgs {
    /// Checks the ranges and the number of coefficients.
    pub fn check(&self) -> Result<(), CliError> {
        DIAMETER_MM.check(self.diameter)?;
        FLUTES.check_int(self.flutes)?;
        HELIX_DEG.check(self.helix)?;
        match &self.coefficients {
            Some(v) if v.len() != 6 => Err(CliError::Usage(format!(
                "--coefficients: {} values; expected 6 (k_tc,k_rc,k_ac [N/mm^2], \
                 k_te,k_re,k_ae [N/mm])",
                super::count(v.len())
            ))),
            Some(v) if v.iter().any(|x| !x.is_finite()) => Err(CliError::Usage(format!(
                "--coefficients: {v:?} has a value that is not finite; expected k_tc,k_rc,k_ac \
                 [N/mm^2], k_te,k_re,k_ae [N/mm]"
            ))),
            _ => Ok(()),
        }
    }
}
