//! What the C handles of the two parallel correctors (the paper's five-bar with a 2-D map,
//! the Delta with a 3-D map) share, one code path for both: building the core's `Model` and
//! `Data` from the C arguments, and one tick into the C tick's fields. Generic over the task
//! dimension `N` (2 or 3) and the mechanism and map types.

use deflect_core::dalembert::parallel::{self, Data, DisplacementModel, Model};
use deflect_core::mechanism::Mechanism;
use nalgebra::SVector;

use crate::boundary::array;
use crate::status::{DeflectStatus, build_failure, placement_code, tick_status};

/// A parallel corrector's validated model and its workspace.
#[derive(Debug)]
pub(crate) struct Corrector<M, D, const N: usize> {
    pub model: Model<M, D>,
    pub data: Data<(), (), N>,
}

/// The corrector of `mechanism` with its own copy of the map `map`, mass parameter `mass` m*
/// \[kg\] and the fixed-point settings of the C API (`fixed_point_iterations` 0 is the paper's
/// one-shot update), with a fresh workspace. Init time: allocates.
pub(crate) fn build<M, D, const N: usize>(
    mechanism: M,
    map: D,
    mass: f64,
    fixed_point_iterations: u32,
    tolerance: f64,
) -> Result<Corrector<M, D, N>, (DeflectStatus, String)>
where
    M: Mechanism<N, N, Data = ()>,
    D: DisplacementModel<N, N, Data = ()>,
{
    let model = Model::new(mechanism, map, mass)
        .and_then(|m| m.with_fixed_point(fixed_point_iterations as usize, tolerance))
        .map_err(build_failure)?;
    let data = Data::new(&model);
    Ok(Corrector { model, data })
}

/// The desired point and planned acceleration of a tick, `N` doubles each.
///
/// # Safety
/// `desired` and `acceleration` are NULL or hold `N` readable doubles.
pub(crate) unsafe fn inputs<const N: usize>(
    desired: *const f64,
    acceleration: *const f64,
) -> Result<(SVector<f64, N>, SVector<f64, N>), DeflectStatus> {
    // SAFETY: forwarded caller contract.
    let (x, a) = unsafe { (array::<N>(desired)?, array::<N>(acceleration)?) };
    Ok((SVector::from(x), SVector::from(a)))
}

/// One corrected tick's fields as the C tick structs hold them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TickFields<const N: usize> {
    pub desired: [f64; N],
    pub commanded: [f64; N],
    pub joints: [f64; N],
    pub force: [f64; N],
    pub displacement: [f64; N],
    pub iterations: u32,
    pub fixed_point_residual: f64,
    pub placement: i32,
}

/// One tick of the corrector to `desired` with planned acceleration `acceleration`. Per tick:
/// no allocation.
pub(crate) fn tick<M, D, const N: usize>(
    model: &Model<M, D>,
    data: &mut Data<(), (), N>,
    desired: &SVector<f64, N>,
    acceleration: &SVector<f64, N>,
) -> Result<TickFields<N>, DeflectStatus>
where
    M: Mechanism<N, N, Data = ()>,
    D: DisplacementModel<N, N, Data = ()>,
{
    let t = parallel::step(model, data, desired, acceleration).map_err(|e| tick_status(&e))?;
    Ok(TickFields {
        desired: t.desired.into(),
        commanded: t.commanded.into(),
        joints: t.joints.into(),
        force: t.load.into(),
        displacement: t.displacement.into(),
        iterations: u32::try_from(t.iterations).unwrap_or(u32::MAX),
        fixed_point_residual: t.diagnostics.fixed_point_residual,
        placement: placement_code(t.diagnostics.placement),
    })
}
