//! Compliance maps over 1-4 dimensional grids (deflect-core's `compliance_map::GridMap`):
//! the per-node lines of Paksoy, Dede and Kiper (2025, Eq. 9-13) over task-space `(x, y, z)`
//! or joint coordinates, blended multilinearly or by cubic Hermite, loaded from deflect's JSON
//! (`format_version` 2, or a 2-D map of version 1).

use std::ffi::c_char;

use deflect_core::compliance_map::GridMap;
use deflect_core::io::map_json;

use crate::boundary::{destroy, guard, handle, handle_mut, load_str, slice, slice_mut, write};
use crate::map::query_options;
use crate::status::{DeflectStatus, load_failure, placement_code, tick_status};

/// A compliance map over a grid of 1-4 dimensions. Opaque; create with
/// `deflect_grid_map_from_json` or `deflect_grid_map_load_json`, free with
/// `deflect_grid_map_destroy`.
#[derive(Debug)]
pub struct DeflectGridMap {
    map: GridMap,
}

impl DeflectGridMap {
    /// The map (for the correctors that copy it in).
    pub(crate) fn map(&self) -> &GridMap {
        &self.map
    }
}

/// Loads a grid map from deflect's versioned JSON text (`format_version` 2 with 1-4 named
/// axes, or a 2-D map of version 1; SI units, with its query options). Init time: allocates.
/// On failure `*out` is NULL and `err` receives the message.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (not UTF-8) or
/// `DEFLECT_ERR_LOAD`.
///
/// # Safety
/// `text` is NULL or NUL-terminated; `out` is NULL or writable; `err` is NULL or writable for
/// `err_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_grid_map_from_json(
    text: *const c_char,
    out: *mut *mut DeflectGridMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    // SAFETY: forwarded caller contract.
    unsafe {
        load_str(text, "text", out, err, err_len, |text| {
            let map = map_json::grid_from_str(text).map_err(load_failure)?;
            Ok(DeflectGridMap { map })
        })
    }
}

/// `deflect_grid_map_from_json` on the contents of the file at `path`.
///
/// # Safety
/// As `deflect_grid_map_from_json`, with `path` for `text`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_grid_map_load_json(
    path: *const c_char,
    out: *mut *mut DeflectGridMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    // SAFETY: forwarded caller contract.
    unsafe {
        load_str(path, "path", out, err, err_len, |path| {
            let map = map_json::grid_from_path(path).map_err(load_failure)?;
            Ok(DeflectGridMap { map })
        })
    }
}

/// Frees a grid map handle. NULL is a no-op.
///
/// # Safety
/// `map` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_grid_map_destroy(map: *mut DeflectGridMap) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(map) };
        Ok(())
    });
}

/// Writes the map's grid dimensions to `*dims`, force axes to `*n_force` and displacement
/// axes to `*n_displacement` (any may be NULL).
///
/// # Safety
/// `map` is NULL or a live handle; the outputs are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_grid_map_shape(
    map: *const DeflectGridMap,
    dims: *mut usize,
    n_force: *mut usize,
    n_displacement: *mut usize,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle(map) }?;
        for (p, v) in [
            (dims, m.map.dims()),
            (n_force, m.map.n_force()),
            (n_displacement, m.map.n_displacement()),
        ] {
            if !p.is_null() {
                // SAFETY: non-null, writable by contract.
                unsafe { write(p, v) }?;
            }
        }
        Ok(())
    })
}

/// Sets the map's query options: `interpolation` is `DEFLECT_INTERPOLATION_BILINEAR`
/// (multilinear in N-D) or `_BICUBIC` (cubic Hermite), `out_of_grid` `DEFLECT_OUT_OF_GRID_*`.
/// Returns `DEFLECT_ERR_NULL` or `DEFLECT_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `map` is NULL or a live handle not read by another thread meanwhile.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_grid_map_set_options(
    map: *mut DeflectGridMap,
    interpolation: i32,
    out_of_grid: i32,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle_mut(map) }?;
        m.map = m
            .map
            .clone()
            .with_options(query_options(interpolation, out_of_grid)?);
        Ok(())
    })
}

/// Displacement `out[out_len]` \[m | rad\] at `point[point_len]` (one coordinate per grid
/// axis) under `force[force_len]` \[N | N m\], with the map's options. `status` (may be NULL)
/// receives `DEFLECT_QUERY_INSIDE`, `_CLAMPED` or `_EXTRAPOLATED`. Per tick: no allocation.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH`, `DEFLECT_ERR_NON_FINITE` or
/// `DEFLECT_ERR_OUT_OF_GRID`.
///
/// # Safety
/// `map` is NULL or a live handle; `point` holds `point_len` doubles, `force` `force_len`,
/// `out` `out_len` writable doubles; `status` is NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)] // reason: pointer and length pairs of the C signature
pub unsafe extern "C" fn deflect_grid_map_displacement(
    map: *const DeflectGridMap,
    point: *const f64,
    point_len: usize,
    force: *const f64,
    force_len: usize,
    out: *mut f64,
    out_len: usize,
    status: *mut i32,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (m, p, f, o) = unsafe {
            (
                handle(map)?,
                slice(point, point_len)?,
                slice(force, force_len)?,
                slice_mut(out, out_len)?,
            )
        };
        let s = m.map.displacement(p, f, o).map_err(|e| tick_status(&e))?;
        if !status.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(status, placement_code(s)) }?;
        }
        Ok(())
    })
}
