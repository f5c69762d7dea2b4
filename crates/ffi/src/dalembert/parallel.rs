//! The D'Alembert trajectory corrector of Paksoy, Dede and Kiper (2025) for their 2-DoF planar
//! parallel robot: `F_D = -m* a` (Eq. 5) through the compliance map to a corrected point and
//! closed-form inverse kinematics, every servo tick.

use deflect_core::ComplianceMap;
use deflect_core::dalembert::parallel::{self, Data, Model};
use deflect_core::mechanism::ParallelRobot2;

use super::corrector;
use crate::boundary::{destroy, guard, handle, handle_mut, load, write};
use crate::map::DeflectComplianceMap;
use crate::status::{DEFLECT_ERR_NULL, DeflectStatus, build_failure};

/// The paper's tuned D'Alembert mass parameter m* \[kg\].
pub const DEFLECT_PAPER_MASS: f64 = 5.0;

const _: () = assert!(DEFLECT_PAPER_MASS == parallel::PAPER_MASS);

/// Geometry of the paper's 2-DoF planar parallel robot (Paksoy et al., section 4.1).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeflectParallelRobot2 {
    /// Length of every arm link \[m\] (paper: 0.150).
    pub link: f64,
    /// Distance of the base pivots from the base centre \[m\] (paper: 0.090).
    pub half_width: f64,
    /// Singularity threshold: smallest allowed Jacobian singular value \[m/rad\] (0.020).
    pub min_sigma: f64,
}

/// One corrected tick of the D'Alembert corrector of the planar robot.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeflectCorrectedTick2 {
    /// Desired (planned) point \[m\].
    pub desired: [f64; 2],
    /// Commanded point \[m\]: desired minus the predicted displacement.
    pub commanded: [f64; 2],
    /// Joint command (theta_A, theta_B) \[rad\]: inverse kinematics of `commanded`.
    pub joints: [f64; 2],
    /// D'Alembert force -m* a \[N\].
    pub force: [f64; 2],
    /// Predicted displacement at the commanded point \[m\].
    pub displacement: [f64; 2],
    /// Fixed-point iterations done (0 = the paper's one-shot update).
    pub iterations: u32,
    /// |c_k - c_(k-1)| of the last fixed-point iteration \[m\] (0 without iterations).
    pub fixed_point_residual: f64,
    /// Worst placement of the map queries: `DEFLECT_QUERY_INSIDE`, `_CLAMPED` or
    /// `_EXTRAPOLATED`.
    pub placement: i32,
}

/// The D'Alembert trajectory corrector of the planar parallel robot (Paksoy et al.,
/// section 3.3): robot geometry, its own copy of the compliance map, settings, and the last
/// tick's joints. Opaque; create with `deflect_dalembert_create`, free with
/// `deflect_dalembert_destroy`. Not thread-safe: one thread at a time.
#[derive(Debug)]
pub struct DeflectDalembert {
    model: Model<ParallelRobot2, ComplianceMap>,
    data: Data<(), (), 2>,
}

/// Writes the geometry of the paper's robot (L = 0.150 m, pivots 0.090 m from the centre,
/// singularity threshold 0.020 m/rad) to `*out`.
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_parallel_robot2_paper(
    out: *mut DeflectParallelRobot2,
) -> DeflectStatus {
    guard(|| {
        let r = ParallelRobot2::paper();
        let value = DeflectParallelRobot2 {
            link: r.link(),
            half_width: r.half_width(),
            min_sigma: r.min_sigma(),
        };
        // SAFETY: NULL or writable by contract.
        unsafe { write(out, value) }
    })
}

/// Creates a D'Alembert corrector (Paksoy et al., section 3.3) for the planar parallel robot
/// `robot` (NULL = the paper's robot) with the compliance map `map` (copied into the
/// corrector; it must have 2 force and 2 displacement axes, and its options decide what
/// happens outside its grid) and mass parameter `mass` m* \[kg\] (finite, >= 0; the paper's is
/// `DEFLECT_PAPER_MASS`). With `fixed_point_iterations = 0` each step is the paper's one-shot
/// update; otherwise the command is iterated `c = x_d - d(c, F)` at most that often, stopping
/// once successive commands differ by at most `tolerance` \[m\] (finite, >= 0). Init time:
/// allocates the handle. On failure `*out` is NULL.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_MAP_DIMENSION` or
/// `DEFLECT_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// `robot` is NULL or readable; `map` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_dalembert_create(
    robot: *const DeflectParallelRobot2,
    map: *const DeflectComplianceMap,
    mass: f64,
    fixed_point_iterations: u32,
    tolerance: f64,
    out: *mut *mut DeflectDalembert,
) -> DeflectStatus {
    let make = || {
        // SAFETY: NULL or readable by contract.
        let robot = match unsafe { robot.as_ref() } {
            None => ParallelRobot2::paper(),
            Some(r) => {
                ParallelRobot2::new(r.link, r.half_width, r.min_sigma).map_err(build_failure)?
            }
        };
        // SAFETY: NULL or a live handle by contract.
        let map = unsafe { handle(map) }.map_err(|s| (s, "map is NULL".to_owned()))?;
        let corrector::Corrector { model, data } = corrector::build(
            robot,
            map.map.clone(),
            mass,
            fixed_point_iterations,
            tolerance,
        )?;
        Ok(DeflectDalembert { model, data })
    };
    // SAFETY: forwarded caller contract for `out`.
    unsafe { load(out, std::ptr::null_mut(), 0, make) }
}

/// Frees a corrector handle. NULL is a no-op.
///
/// # Safety
/// `corrector` is NULL or a live handle, not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_dalembert_destroy(corrector: *mut DeflectDalembert) {
    let _ = guard(|| {
        // SAFETY: forwarded caller contract (NULL or a live handle, freed once).
        unsafe { destroy(corrector) };
        Ok(())
    });
}

/// One corrector tick: desired point `desired[2]` \[m\] with planned acceleration
/// `acceleration[2]` \[m/s^2\] (from `deflect_trajectory2_sample`). The D'Alembert force
/// `-m* a` (Eq. 5), the map's displacement at the desired (or fixed-point) point, the command
/// `desired - displacement` and its inverse kinematics go to `*out`. Per tick: no
/// allocation, bounded time.
///
/// Returns `DEFLECT_ERR_NULL`, `DEFLECT_ERR_NON_FINITE`, `DEFLECT_ERR_OUT_OF_GRID`,
/// `DEFLECT_ERR_OUT_OF_WORKSPACE` or `DEFLECT_ERR_SINGULAR`.
///
/// # Safety
/// `corrector` is NULL or a live handle not used by another thread; `desired` and
/// `acceleration` hold 2 doubles; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn deflect_dalembert_step(
    corrector: *mut DeflectDalembert,
    desired: *const f64,
    acceleration: *const f64,
    out: *mut DeflectCorrectedTick2,
) -> DeflectStatus {
    guard(|| {
        // SAFETY: pointers valid for the stated lengths (or NULL) by contract.
        let (c, (x, a)) = unsafe {
            (
                handle_mut(corrector)?,
                corrector::inputs::<2>(desired, acceleration)?,
            )
        };
        if out.is_null() {
            return Err(DEFLECT_ERR_NULL);
        }
        let t = corrector::tick(&c.model, &mut c.data, &x, &a)?;
        let tick = DeflectCorrectedTick2 {
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
