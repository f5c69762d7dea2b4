//! Compliance maps of Paksoy, Dede and Kiper (2025): per-node force-displacement lines
//! (Eq. 9-13) blended over an (x, y) grid (Eq. 14), loaded from the paper's CSV tables or
//! deflect's JSON.

use std::ffi::c_char;

use deflect_core::compliance_map::{ComplianceMap, Interpolation, OutOfGrid, QueryOptions};
use deflect_core::io::{map_csv, map_json};
use deflect_core::units::{ForceUnit, LengthUnit};

use crate::boundary::{
    array, destroy, guard, handle, handle_mut, load_str, slice, slice_mut, write,
};
use crate::status::{
    DEFLECT_ERR_INVALID_ARGUMENT, DeflectStatus, load_failure, placement_code, tick_status,
};

/// File force unit: newton.
pub const DEFLECT_FORCE_UNIT_NEWTON: i32 = 0;
/// File force unit: kilogram-force (9.80665 N).
pub const DEFLECT_FORCE_UNIT_KGF: i32 = 1;
/// File length unit: metre.
pub const DEFLECT_LENGTH_UNIT_METRE: i32 = 0;
/// File length unit: millimetre.
pub const DEFLECT_LENGTH_UNIT_MILLIMETRE: i32 = 1;
/// Map interpolation: bilinear between the 4 nodes of the cell (the paper's Eq. 14).
pub const DEFLECT_INTERPOLATION_BILINEAR: i32 = 0;
/// Map interpolation: tensor-product cubic Hermite (C1).
pub const DEFLECT_INTERPOLATION_BICUBIC: i32 = 1;
/// Outside the map's grid: refuse with `DEFLECT_ERR_OUT_OF_GRID` (the default).
pub const DEFLECT_OUT_OF_GRID_ERROR: i32 = 0;
/// Outside the map's grid: clamp the position to the grid boundary.
pub const DEFLECT_OUT_OF_GRID_CLAMP: i32 = 1;
/// Outside the map's grid: extrapolate linearly from the boundary.
pub const DEFLECT_OUT_OF_GRID_EXTRAPOLATE: i32 = 2;
/// The query options of the codes `DEFLECT_INTERPOLATION_*` and `DEFLECT_OUT_OF_GRID_*`;
/// `DEFLECT_ERR_INVALID_ARGUMENT` for an unknown code.
pub(crate) fn query_options(interpolation: i32, out_of_grid: i32) -> Result<QueryOptions, i32> {
    let interpolation = match interpolation {
        DEFLECT_INTERPOLATION_BILINEAR => Interpolation::Bilinear,
        DEFLECT_INTERPOLATION_BICUBIC => Interpolation::Bicubic,
        _ => return Err(DEFLECT_ERR_INVALID_ARGUMENT),
    };
    let out_of_grid = match out_of_grid {
        DEFLECT_OUT_OF_GRID_ERROR => OutOfGrid::Error,
        DEFLECT_OUT_OF_GRID_CLAMP => OutOfGrid::Clamp,
        DEFLECT_OUT_OF_GRID_EXTRAPOLATE => OutOfGrid::Extrapolate,
        _ => return Err(DEFLECT_ERR_INVALID_ARGUMENT),
    };
    Ok(QueryOptions {
        interpolation,
        out_of_grid,
    })
}

/// A compliance map (per-node force-displacement lines over an (x, y) grid). Opaque; create
/// with `deflect_compliance_map_from_paper_csv`, `_load_paper_csv`, `_from_json` or
/// `_load_json`, free with `deflect_compliance_map_destroy`.
#[derive(Debug)]
pub struct DeflectComplianceMap {
    pub(crate) map: ComplianceMap,
}

fn units(force_unit: i32, length_unit: i32) -> Result<(ForceUnit, LengthUnit), (i32, String)> {
    let force = match force_unit {
        DEFLECT_FORCE_UNIT_NEWTON => ForceUnit::Newton,
        DEFLECT_FORCE_UNIT_KGF => ForceUnit::KilogramForce,
        other => {
            return Err((
                DEFLECT_ERR_INVALID_ARGUMENT,
                format!("unknown force unit code {other} (0 = N, 1 = kgf)"),
            ));
        }
    };
    let length = match length_unit {
        DEFLECT_LENGTH_UNIT_METRE => LengthUnit::Metre,
        DEFLECT_LENGTH_UNIT_MILLIMETRE => LengthUnit::Millimetre,
        other => {
            return Err((
                DEFLECT_ERR_INVALID_ARGUMENT,
                format!("unknown length unit code {other} (0 = m, 1 = mm)"),
            ));
        }
    };
    Ok((force, length))
}

/// Loads a compliance map from CSV text in the layout of the paper's coefficient tables
/// (Paksoy et al., Tables II/III: columns `x_mm, y_mm` (or `x_m, y_m`, or `x, y` in
/// `length_unit`) and `m, n, o, p, s, u, v, w`). `force_unit` is `DEFLECT_FORCE_UNIT_*` (the
/// unit the lines were fitted in), `length_unit` is `DEFLECT_LENGTH_UNIT_*` (unit of the
/// displacements). Converted to SI. Init time: allocates. On failure `*out` is NULL and `err`
/// receives the message.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (unit code, not UTF-8) or
/// `DEFLECT_ERR_LOAD`.
///
/// # Safety
/// `text` is NULL or NUL-terminated; `out` is NULL or writable; `err` is NULL or writable for
/// `err_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_from_paper_csv(
    text: *const c_char,
    force_unit: i32,
    length_unit: i32,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    // SAFETY: forwarded caller contract.
    unsafe {
        load_str(text, "text", out, err, err_len, |text| {
            let (f, l) = units(force_unit, length_unit)?;
            let map = map_csv::from_str(text, f, l).map_err(load_failure)?;
            Ok(DeflectComplianceMap { map })
        })
    }
}

/// `deflect_compliance_map_from_paper_csv` on the contents of the file at `path`.
///
/// # Safety
/// As `deflect_compliance_map_from_paper_csv`, with `path` for `text`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_load_paper_csv(
    path: *const c_char,
    force_unit: i32,
    length_unit: i32,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    // SAFETY: forwarded caller contract.
    unsafe {
        load_str(path, "path", out, err, err_len, |path| {
            let (f, l) = units(force_unit, length_unit)?;
            let map = map_csv::from_path(path, f, l).map_err(load_failure)?;
            Ok(DeflectComplianceMap { map })
        })
    }
}

/// Loads a compliance map from deflect's versioned JSON text (`format_version` 1, SI units,
/// any number of force and displacement axes, with its query options). Init time: allocates.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (not UTF-8) or
/// `DEFLECT_ERR_LOAD`.
///
/// # Safety
/// `text` is NULL or NUL-terminated; `out` is NULL or writable; `err` is NULL or writable for
/// `err_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_from_json(
    text: *const c_char,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    // SAFETY: forwarded caller contract.
    unsafe {
        load_str(text, "text", out, err, err_len, |text| {
            let map = map_json::from_str(text).map_err(load_failure)?;
            Ok(DeflectComplianceMap { map })
        })
    }
}

/// `deflect_compliance_map_from_json` on the contents of the file at `path`.
///
/// # Safety
/// As `deflect_compliance_map_from_json`, with `path` for `text`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_load_json(
    path: *const c_char,
    out: *mut *mut DeflectComplianceMap,
    err: *mut c_char,
    err_len: usize,
) -> DeflectStatus {
    // SAFETY: forwarded caller contract.
    unsafe {
        load_str(path, "path", out, err, err_len, |path| {
            let map = map_json::from_path(path).map_err(load_failure)?;
            Ok(DeflectComplianceMap { map })
        })
    }
}

/// Frees a map handle. NULL is a no-op.
///
/// # Safety
/// `map` is NULL or a live handle, not used afterwards (and by no corrector call in flight).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_destroy(map: *mut DeflectComplianceMap) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(map) };
        Ok(())
    });
}

/// Sets the map's query options: `interpolation` is `DEFLECT_INTERPOLATION_*`, `out_of_grid`
/// is `DEFLECT_OUT_OF_GRID_*`. A map loaded from CSV starts bilinear with
/// `DEFLECT_OUT_OF_GRID_ERROR`. Returns `DEFLECT_ERR_NULL` or `DEFLECT_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `map` is NULL or a live handle not read by another thread meanwhile.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_set_options(
    map: *mut DeflectComplianceMap,
    interpolation: i32,
    out_of_grid: i32,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle_mut(map) }?;
        m.map
            .set_options(query_options(interpolation, out_of_grid)?);
        Ok(())
    })
}

/// Writes the map's number of force axes to `*n_force` and of displacement axes to
/// `*n_displacement` (either may be NULL). The paper's tables give 2 and 2.
///
/// # Safety
/// `map` is NULL or a live handle; the outputs are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_axes(
    map: *const DeflectComplianceMap,
    n_force: *mut usize,
    n_displacement: *mut usize,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: live handle or NULL by contract.
        let m = unsafe { handle(map) }?;
        if !n_force.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(n_force, m.map.n_force()) }?;
        }
        if !n_displacement.is_null() {
            // SAFETY: non-null, writable by contract.
            unsafe { write(n_displacement, m.map.n_displacement()) }?;
        }
        Ok(())
    })
}

/// Displacement `out[out_len]` \[m | rad\] at `position[2] = (x, y)` \[m\] under
/// `force[force_len]` \[N | N m\], with the map's options (Eq. 9-10 at nodes, Eq. 14 between
/// them). `force_len` must equal the map's force axes and `out_len` its displacement axes.
/// `status` (may be NULL) receives `DEFLECT_QUERY_INSIDE`, `_CLAMPED` or `_EXTRAPOLATED`.
/// Per tick: no allocation.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_WRONG_LENGTH`, `DEFLECT_ERR_NON_FINITE` or
/// `DEFLECT_ERR_OUT_OF_GRID`.
///
/// # Safety
/// `map` is NULL or a live handle; `position` holds 2 doubles, `force` `force_len`, `out`
/// `out_len` writable doubles; `status` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_compliance_map_displacement(
    map: *const DeflectComplianceMap,
    position: *const f64,
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
                array::<2>(position)?,
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
