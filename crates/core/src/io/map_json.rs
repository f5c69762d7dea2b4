//! Compliance maps as versioned JSON (`std`): SI units recorded, coefficients in a recorded
//! layout, floats in shortest round-trip form so that a map is restored bit for bit.
//!
//! Version 1 is the 2-D [`ComplianceMap`] (`x`, `y` and its fit statistics), still what
//! [`to_string`] writes so that files stay readable by earlier deflect versions. Version 2
//! holds a [`GridMap`] of 1-4 named axes (`"axes": [{"name": "x", "nodes": [...]}, ...]`),
//! written by [`grid_to_string`]. [`grid_from_str`] reads both; [`from_str`] reads both when
//! the grid is 2-D.

use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::compliance_map::{ComplianceMap, GridMap, NodeFit, QueryOptions};
use crate::error::{BuildError, LoadError};

/// Version of the 2-D map's JSON (`"format_version": 1`).
pub const FORMAT_VERSION: u64 = 1;

/// Version of the N-D grid map's JSON (`"format_version": 2`).
pub const GRID_FORMAT_VERSION: u64 = 2;

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

/// Loads a 2-D map saved by [`to_string`] (version 1) or [`grid_to_string`] (version 2 with
/// two axes, the first x); refuses other format versions, non-SI units and inconsistent
/// arrays.
pub fn from_str(text: &str) -> Result<ComplianceMap, LoadError> {
    super::check_size("JSON map", text)?;
    let probe: Probe = serde_json::from_str(text).map_err(json_err)?;
    match probe.format_version {
        FORMAT_VERSION => from_v1(text),
        GRID_FORMAT_VERSION => {
            let grid = grid_from_v2(text)?;
            match grid.axes() {
                [x, y] => {
                    let (nf, nd) = (grid.n_force(), grid.n_displacement());
                    Ok(ComplianceMap::new(
                        x.clone(),
                        y.clone(),
                        nf,
                        nd,
                        grid.slopes().to_vec(),
                        grid.offsets().to_vec(),
                    )?
                    .with_options(grid.options()))
                }
                axes => Err(LoadError::Build(BuildError::InvalidParameter {
                    what: "grid dimensions of a 2-D compliance map (a GridMap reads 1-4)",
                    value: axes.len() as f64,
                    expected: "2",
                })),
            }
        }
        found => Err(LoadError::UnsupportedVersion { found }),
    }
}

fn json_err(e: serde_json::Error) -> LoadError {
    LoadError::Json {
        message: e.to_string(),
    }
}

fn check_units(units: &JsonUnits) -> Result<(), LoadError> {
    let si = JsonUnits::si();
    for (quantity, found, want) in [
        ("position", &units.position, &si.position),
        ("force", &units.force, &si.force),
        ("displacement", &units.displacement, &si.displacement),
    ] {
        if found != want {
            return Err(LoadError::UnexpectedUnits {
                quantity,
                found: found.clone(),
            });
        }
    }
    Ok(())
}

fn from_v1(text: &str) -> Result<ComplianceMap, LoadError> {
    let doc: JsonMap = serde_json::from_str(text).map_err(json_err)?;
    check_units(&doc.units)?;
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

fn grid_from_v2(text: &str) -> Result<GridMap, LoadError> {
    let doc: JsonGrid = serde_json::from_str(text).map_err(json_err)?;
    check_units(&doc.units)?;
    let (names, axes) = doc.axes.into_iter().map(|a| (a.name, a.nodes)).unzip();
    Ok(GridMap::new(
        axes,
        names,
        doc.n_force,
        doc.n_displacement,
        doc.slopes,
        doc.offsets,
    )?
    .with_options(doc.options))
}

/// Saves a grid map as JSON `"format_version": 2`: SI units, named axes, coefficients in the
/// layout recorded under `"layout"`, the default query options; floats in shortest
/// round-trip form, so [`grid_from_str`] restores the map bit for bit.
pub fn grid_to_string(map: &GridMap) -> Result<String, LoadError> {
    let doc = JsonGrid {
        format_version: GRID_FORMAT_VERSION,
        units: JsonUnits::si(),
        layout: GRID_LAYOUT.to_string(),
        n_force: map.n_force(),
        n_displacement: map.n_displacement(),
        axes: map
            .names()
            .iter()
            .zip(map.axes())
            .map(|(name, nodes)| JsonAxis {
                name: name.clone(),
                nodes: nodes.clone(),
            })
            .collect(),
        slopes: map.slopes().to_vec(),
        offsets: map.offsets().to_vec(),
        options: map.options(),
    };
    serde_json::to_string_pretty(&doc).map_err(json_err)
}

/// Loads a grid map: version 2 ([`grid_to_string`]) or version 1 (a 2-D map over axes `x`,
/// `y`; its fit statistics are not kept).
pub fn grid_from_str(text: &str) -> Result<GridMap, LoadError> {
    super::check_size("JSON map", text)?;
    let probe: Probe = serde_json::from_str(text).map_err(json_err)?;
    match probe.format_version {
        FORMAT_VERSION => Ok(GridMap::from_map(&from_v1(text)?)),
        GRID_FORMAT_VERSION => grid_from_v2(text),
        found => Err(LoadError::UnsupportedVersion { found }),
    }
}

/// [`grid_from_str`] on the text of the file at `path`.
pub fn grid_from_path(path: impl AsRef<Path>) -> Result<GridMap, LoadError> {
    grid_from_str(&super::read_text(path.as_ref())?)
}

/// Writes [`grid_to_string`] to the file at `path`.
pub fn grid_to_path(map: &GridMap, path: impl AsRef<Path>) -> Result<(), LoadError> {
    let path = path.as_ref();
    std::fs::write(path, grid_to_string(map)?).map_err(|e| LoadError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    })
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

const GRID_LAYOUT: &str = "node = sum_k i_k * stride_k, the last axis fastest; index = (node * \
                           n_displacement + d) * n_force + f; disp_d = sum_f (slopes[index] * \
                           F_f + offsets[index])";

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonAxis {
    name: String,
    nodes: Vec<f64>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonGrid {
    format_version: u64,
    units: JsonUnits,
    layout: String,
    n_force: usize,
    n_displacement: usize,
    axes: Vec<JsonAxis>,
    slopes: Vec<f64>,
    offsets: Vec<f64>,
    options: QueryOptions,
}

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
