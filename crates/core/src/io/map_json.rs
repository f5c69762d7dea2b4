//! Compliance maps as versioned JSON (`std`): SI units recorded, coefficients in a recorded
//! layout, floats in shortest round-trip form so that a map is restored bit for bit.

use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::compliance_map::{ComplianceMap, NodeFit, QueryOptions};
use crate::error::{BuildError, LoadError};

/// Version written to and required from JSON maps (`"format_version": 1`).
pub const FORMAT_VERSION: u64 = 1;

/// Saves the map as JSON (`"format_version": 1`), SI units recorded under `"units"`,
/// coefficients in the layout recorded under `"layout"`, the default query options and
/// the fit statistics if any. Floats are written in shortest round-trip form, so
/// [`from_str`] restores the map bit for bit.
pub fn to_string(map: &ComplianceMap) -> Result<String, LoadError> {
    let doc = JsonMap {
        format_version: FORMAT_VERSION,
        units: JsonUnits::si(),
        layout: LAYOUT.to_string(),
        n_force: map.n_force(),
        n_displacement: map.n_displacement(),
        x: map.x().to_vec(),
        y: map.y().to_vec(),
        slopes: map.slopes().to_vec(),
        offsets: map.offsets().to_vec(),
        options: map.options(),
        fit: map.fit_stats().map(<[NodeFit]>::to_vec),
    };
    serde_json::to_string_pretty(&doc).map_err(|e| LoadError::Json {
        message: e.to_string(),
    })
}

/// Loads a map saved by [`to_string`]; refuses other format versions, non-SI units
/// and inconsistent arrays.
pub fn from_str(text: &str) -> Result<ComplianceMap, LoadError> {
    super::check_size("JSON map", text)?;
    let json_err = |e: serde_json::Error| LoadError::Json {
        message: e.to_string(),
    };
    let probe: Probe = serde_json::from_str(text).map_err(json_err)?;
    if probe.format_version != FORMAT_VERSION {
        return Err(LoadError::UnsupportedVersion {
            found: probe.format_version,
        });
    }
    let doc: JsonMap = serde_json::from_str(text).map_err(json_err)?;
    let si = JsonUnits::si();
    for (quantity, found, want) in [
        ("position", &doc.units.position, &si.position),
        ("force", &doc.units.force, &si.force),
        ("displacement", &doc.units.displacement, &si.displacement),
    ] {
        if found != want {
            return Err(LoadError::UnexpectedUnits {
                quantity,
                found: found.clone(),
            });
        }
    }
    let mut map = ComplianceMap::new(
        doc.x,
        doc.y,
        doc.n_force,
        doc.n_displacement,
        doc.slopes,
        doc.offsets,
    )?
    .with_options(doc.options);
    if let Some(fit) = &doc.fit {
        let nodes = map.x().len() * map.y().len();
        if fit.len() != nodes {
            return Err(LoadError::Build(BuildError::WrongLength {
                what: "fit",
                expected: nodes,
                got: fit.len(),
            }));
        }
    }
    map.set_fit_stats(doc.fit);
    Ok(map)
}

/// [`from_str`] on the text of the file at `path`.
pub fn from_path(path: impl AsRef<Path>) -> Result<ComplianceMap, LoadError> {
    from_str(&super::read_text(path.as_ref())?)
}

/// Writes [`to_string`] to the file at `path`.
pub fn to_path(map: &ComplianceMap, path: impl AsRef<Path>) -> Result<(), LoadError> {
    let path = path.as_ref();
    std::fs::write(path, to_string(map)?).map_err(|e| LoadError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

const LAYOUT: &str = "index = ((i * ny + j) * n_displacement + d) * n_force + f; \
                      disp_d = sum_f (slopes[index] * F_f + offsets[index])";

#[derive(Debug, Deserialize)]
struct Probe {
    format_version: u64,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonUnits {
    position: String,
    force: String,
    displacement: String,
    slope: String,
}

impl JsonUnits {
    fn si() -> Self {
        Self {
            position: "m".to_string(),
            force: "N (moments N m)".to_string(),
            displacement: "m (rotations rad)".to_string(),
            slope: "displacement unit / force unit".to_string(),
        }
    }
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonMap {
    format_version: u64,
    units: JsonUnits,
    layout: String,
    n_force: usize,
    n_displacement: usize,
    x: Vec<f64>,
    y: Vec<f64>,
    slopes: Vec<f64>,
    offsets: Vec<f64>,
    options: QueryOptions,
    #[serde(default)]
    fit: Option<Vec<NodeFit>>,
}
