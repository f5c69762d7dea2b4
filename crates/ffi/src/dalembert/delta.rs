//! The D'Alembert corrector of Paksoy, Dede and Kiper (2025, section 3.3) on a Delta robot
//! (Clavel's 3-DoF parallel robot) with a 3-D task-space compliance map: `F_D = -m* a` (Eq. 5)
//! through the map to a corrected platform point and closed-form inverse kinematics, every
//! servo tick.

use deflect_core::compliance_map::GridMap;
use deflect_core::dalembert::parallel::{Data, Model};
use deflect_core::mechanism::Delta;
use nalgebra::Vector3;

use super::corrector;
use crate::boundary::{array, destroy, guard, handle, handle_mut, load, write};
use crate::grid_map::DeflectGridMap;
use crate::status::{DEFLECT_ERR_NULL, DeflectStatus, build_failure, tick_status};

/// Geometry of a Delta robot \[m\] and its singularity threshold \[m/rad\].
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeflectDelta {
    /// Radius of the circle of the actuated joints \[m\].
    pub base_radius: f64,
    /// Radius of the circle of the platform joints \[m\].
    pub platform_radius: f64,
    /// Arm length \[m\].
    pub arm: f64,
    /// Forearm (parallelogram) length \[m\].
    pub forearm: f64,
    /// Smallest allowed Jacobian singular value \[m/rad\] (default 0.010).
    pub min_sigma: f64,
}

fn delta_of(d: &DeflectDelta) -> Result<Delta, (i32, String)> {
    Delta::new(d.base_radius, d.platform_radius, d.arm, d.forearm)
        .and_then(|x| x.with_min_sigma(d.min_sigma))
        .map_err(build_failure)
}

/// One corrected tick of the Delta's D'Alembert corrector.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectCorrectedTick3 {
    /// Desired (planned) platform centre \[m\].
    pub desired: [f64; 3],
    /// Commanded point \[m\]: desired minus the predicted displacement.
    pub commanded: [f64; 3],
    /// Joint command \[rad\]: inverse kinematics of `commanded`.
    pub joints: [f64; 3],
    /// D'Alembert force -m* a \[N\].
    pub force: [f64; 3],
    /// Predicted displacement at the commanded point \[m\].
    pub displacement: [f64; 3],
    /// Fixed-point iterations done (0 = the paper's one-shot update).
    pub iterations: u32,
    /// |c_k - c_(k-1)| of the last fixed-point iteration \[m\] (0 without iterations).
    pub fixed_point_residual: f64,
    /// Worst placement of the map queries: `DEFLECT_QUERY_INSIDE`, `_CLAMPED` or
    /// `_EXTRAPOLATED`.
    pub placement: i32,
}

/// The D'Alembert corrector of a Delta robot: geometry, its own copy of the 3-D map,
/// settings and the last tick's joints. Opaque; create with `deflect_delta_corrector_create`,
/// free with `deflect_delta_corrector_destroy`. Not thread-safe: one thread at a time.
#[derive(Debug)]
pub struct DeflectDeltaCorrector {
    model: Model<Delta, GridMap>,
    data: Data<(), (), 3>,
}

/// Writes deflect's pick-and-place Delta (base radius 0.2 m, platform 0.045 m, arm 0.35 m,
/// forearm 0.8 m, threshold 0.010 m/rad) to `*out`.
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_delta_pick_and_place(out: *mut DeflectDelta) -> DeflectStatus {
    guard(|| {
        let d = Delta::pick_and_place();
        let value = DeflectDelta {
            base_radius: d.base_radius(),
            platform_radius: d.platform_radius(),
            arm: d.arm(),
            forearm: d.forearm(),
            min_sigma: d.min_sigma(),
        };
        // SAFETY: NULL or writable by contract.
        unsafe { write(out, value) }
    })
}

/// Inverse kinematics of `delta`: the joints `q[3]` \[rad\] putting the platform centre on
/// `p[3]` \[m\] (elbows out). Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT` (bad
/// geometry), `DEFLECT_ERR_NON_FINITE` or `DEFLECT_ERR_OUT_OF_WORKSPACE`.
///
/// # Safety
/// `delta` is NULL or readable; `p` holds 3 doubles; `q` is NULL or holds 3 writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_delta_ik(
    delta: *const DeflectDelta,
    p: *const f64,
    q: *mut f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: NULL or readable, 3 doubles by contract.
        let (d, p) = unsafe { (handle(delta)?, array::<3>(p)?) };
        let d = delta_of(d).map_err(|e| e.0)?;
        let v = d.ik(&Vector3::from(p)).map_err(|e| tick_status(&e))?;
        // SAFETY: NULL or 3 writable doubles by contract.
        unsafe { write(q.cast::<[f64; 3]>(), [v.x, v.y, v.z]) }
    })
}

/// Forward kinematics of `delta`: the platform centre `p[3]` \[m\] at joints `q[3]` \[rad\].
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_INVALID_ARGUMENT`, `DEFLECT_ERR_NON_FINITE`,
/// `DEFLECT_ERR_OUT_OF_WORKSPACE` (cannot be assembled) or `DEFLECT_ERR_SINGULAR`.
///
/// # Safety
/// `delta` is NULL or readable; `q` holds 3 doubles; `p` is NULL or holds 3 writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_delta_fk(
    delta: *const DeflectDelta,
    q: *const f64,
    p: *mut f64,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: NULL or readable, 3 doubles by contract.
        let (d, q) = unsafe { (handle(delta)?, array::<3>(q)?) };
        let d = delta_of(d).map_err(|e| e.0)?;
        let v = d.fk(&Vector3::from(q)).map_err(|e| tick_status(&e))?;
        // SAFETY: NULL or 3 writable doubles by contract.
        unsafe { write(p.cast::<[f64; 3]>(), [v.x, v.y, v.z]) }
    })
}

/// Creates the D'Alembert corrector of `delta` (NULL = the pick-and-place Delta) with the 3-D
/// grid map `map` (copied in; 3 axes over x, y, z with 3 force and 3 displacement axes) and
/// mass parameter `mass` m* \[kg\]; fixed-point settings as `deflect_dalembert_create`. Init
/// time: allocates. On failure `*out` is NULL.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_MAP_DIMENSION` or
/// `DEFLECT_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `delta` is NULL or readable; `map` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_delta_corrector_create(
    delta: *const DeflectDelta,
    map: *const DeflectGridMap,
    mass: f64,
    fixed_point_iterations: u32,
    tolerance: f64,
    out: *mut *mut DeflectDeltaCorrector,
) -> DeflectStatus {
    let make = || {
        // SAFETY: NULL or readable by contract.
        let d = match unsafe { delta.as_ref() } {
            None => Delta::pick_and_place(),
            Some(d) => delta_of(d)?,
        };
        // SAFETY: NULL or a live handle by contract.
        let map = unsafe { handle(map) }.map_err(|s| (s, "map is NULL".to_owned()))?;
        let corrector::Corrector { model, data } = corrector::build(
            d,
            map.map().clone(),
            mass,
            fixed_point_iterations,
            tolerance,
        )?;
        Ok(DeflectDeltaCorrector { model, data })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Frees a Delta corrector. NULL is a no-op.
///
/// # Safety
/// `corrector` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_delta_corrector_destroy(corrector: *mut DeflectDeltaCorrector) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(corrector) };
        Ok(())
    });
}

/// One tick: desired platform centre `desired[3]` \[m\] with planned acceleration
/// `acceleration[3]` \[m/s^2\]; the result to `*out`. Per tick: no allocation, bounded time.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_OUT_OF_GRID`,
/// `DEFLECT_ERR_OUT_OF_WORKSPACE` or `DEFLECT_ERR_SINGULAR`.
///
/// # Safety
/// `corrector` is NULL or a live handle not used by another thread; `desired` and
/// `acceleration` hold 3 doubles; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_delta_corrector_step(
    corrector: *mut DeflectDeltaCorrector,
    desired: *const f64,
    acceleration: *const f64,
    out: *mut DeflectCorrectedTick3,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (c, (x, a)) = unsafe {
            (
                handle_mut(corrector)?,
                corrector::inputs::<3>(desired, acceleration)?,
            )
        };
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let t = corrector::tick(&c.model, &mut c.data, &x, &a)?;
        let tick = DeflectCorrectedTick3 {
            desired: t.desired,
            commanded: t.commanded,
            joints: t.joints,
            force: t.force,
            displacement: t.displacement,
            iterations: t.iterations,
            fixed_point_residual: t.fixed_point_residual,
            placement: t.placement,
        };
        // SAFETY: non-null (checked), writable by contract.
        unsafe { write(out, tick) }
    })
}
