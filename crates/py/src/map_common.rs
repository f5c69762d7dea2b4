//! What `deflect.ComplianceMap` and `deflect.GridMap` share, one code path for both maps:
//! the query options from their keyword names, the JSON source (text or path) of
//! `from_json`, and the single query into a new or given array.

use std::path::Path;

use deflect_core::LoadError;
use deflect_core::compliance_map::{Interpolation, MAX_AXES, OutOfGrid, QueryOptions};
use pyo3::prelude::*;

use crate::InputError;
use crate::errors::load_err;
use crate::out::emit;

pub(crate) fn parse_interpolation(s: &str) -> PyResult<Interpolation> {
    match s.to_ascii_lowercase().as_str() {
        "bilinear" | "linear" | "multilinear" => Ok(Interpolation::Bilinear),
        "bicubic" | "cubic" => Ok(Interpolation::Bicubic),
        _ => Err(InputError::new_err(format!(
            "interpolation must be \"bilinear\" (\"multilinear\") or \"bicubic\" (\"cubic\"), got {s:?}"
        ))),
    }
}

/// The query options of the Python names (`interpolation`, `out_of_grid`), each checked.
pub(crate) fn query_options(interpolation: &str, out_of_grid: &str) -> PyResult<QueryOptions> {
    Ok(QueryOptions {
        interpolation: parse_interpolation(interpolation)?,
        out_of_grid: parse_out_of_grid(out_of_grid)?,
    })
}

pub(crate) fn parse_out_of_grid(s: &str) -> PyResult<OutOfGrid> {
    match s.to_ascii_lowercase().as_str() {
        "error" => Ok(OutOfGrid::Error),
        "clamp" => Ok(OutOfGrid::Clamp),
        "extrapolate" => Ok(OutOfGrid::Extrapolate),
        _ => Err(InputError::new_err(format!(
            "out_of_grid must be \"error\", \"clamp\" or \"extrapolate\", got {s:?}"
        ))),
    }
}

pub(crate) fn interpolation_name(i: Interpolation) -> &'static str {
    match i {
        Interpolation::Bicubic => "bicubic",
        _ => "bilinear",
    }
}

pub(crate) fn out_of_grid_name(o: OutOfGrid) -> &'static str {
    match o {
        OutOfGrid::Clamp => "clamp",
        OutOfGrid::Extrapolate => "extrapolate",
        _ => "error",
    }
}

/// `defaults` with the keywords given (`None` keeps the map's default), each checked.
pub(crate) fn options_over(
    defaults: QueryOptions,
    interpolation: Option<&str>,
    out_of_grid: Option<&str>,
) -> PyResult<QueryOptions> {
    Ok(QueryOptions {
        interpolation: interpolation.map_or(Ok(defaults.interpolation), parse_interpolation)?,
        out_of_grid: out_of_grid.map_or(Ok(defaults.out_of_grid), parse_out_of_grid)?,
    })
}

/// A map read from `source`: JSON text (a `str` whose first non-blank character is `{`) by
/// `text`, or a path (`str` or `os.PathLike`) by `path`; load failures raised as the file
/// errors and `LoadError` of [`load_err`].
pub(crate) fn json_source<T>(
    source: &Bound<'_, PyAny>,
    text: impl FnOnce(&str) -> Result<T, LoadError>,
    path: impl FnOnce(&Path) -> Result<T, LoadError>,
) -> PyResult<T> {
    match source.extract::<String>() {
        Ok(s) if s.trim_start().starts_with('{') => text(&s),
        Ok(p) => path(Path::new(&p)),
        Err(_) => path(&source.extract::<std::path::PathBuf>().map_err(|_| {
            InputError::new_err("source: expected the JSON text or a path (str or os.PathLike)")
        })?),
    }
    .map_err(load_err)
}

/// One query's `nd` displacements filled by `query`, returned as a new numpy-owned array (the
/// values copied: cheaper than handing over a Rust buffer for a few entries) or into `out`.
pub(crate) fn one_query<'py>(
    py: Python<'py>,
    nd: usize,
    out: Option<&Bound<'py, PyAny>>,
    query: impl FnOnce(&mut [f64]) -> PyResult<deflect_core::Placement>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut buf = [0.0; MAX_AXES];
    let d = buf.get_mut(..nd).unwrap_or(&mut []);
    query(d)?;
    emit(py, d, &[nd], out)
}
