//! The `MachiningJob`'s arguments that take a choice (`spin=`, `blending=`) and the pickled
//! states of its parts (spin, blending, inertia, unit quaternions).

use deflect_core::machining::job;
use deflect_core::machining::path::Blending;
use deflect_core::machining::spin::{SpinMeasure, SpinOptions, SpinSchedule};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use pyo3::prelude::*;

use crate::InputError;
use crate::errors::build_err;
use crate::scalars::real;

/// The tool's spin about its own axis (`spin=`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Spin {
    /// The setup's orientation.
    Keep,
    /// A constant spin \[rad\].
    Constant(f64),
    /// The search's schedule (deflect-core's `machining::spin`), with its options.
    Optimize(SpinOptions),
}

/// `spin`, `spin_step` \[deg\], `spin_rate` (deg/mm, deg/s) and `spin_measure` as pickled:
/// (mode, constant spin [rad], step [rad], per metre [rad/m], per second [rad/s], measure).
pub(crate) type SpinState = (String, f64, f64, f64, f64, String);

impl Spin {
    /// The spin of the keyword arguments; options checked by core.
    pub(crate) fn from_args(
        spin: Option<&Bound<'_, PyAny>>,
        step_deg: f64,
        rate: (f64, f64),
        measure: &str,
    ) -> PyResult<Self> {
        let measure = SpinMeasure::from_name(measure).ok_or_else(|| {
            InputError::new_err(format!(
                "spin_measure: {measure:?}; expected \"normal\", \"position\", \"axial\" or \"lateral\""
            ))
        })?;
        let options = SpinOptions {
            step: step_deg.to_radians(),
            per_metre: rate.0.to_radians() * 1e3,
            per_second: rate.1.to_radians(),
            measure,
            ..SpinOptions::default()
        };
        let Some(spin) = spin else {
            return Ok(Self::Keep);
        };
        if let Ok(name) = spin.extract::<String>() {
            return match name.as_str() {
                "keep" => Ok(Self::Keep),
                "optimize" | "optimise" => {
                    options.validate().map_err(build_err)?;
                    Ok(Self::Optimize(options))
                }
                other => Err(InputError::new_err(format!(
                    "spin: {other:?}; expected \"keep\", \"optimize\" or a spin in degrees"
                ))),
            };
        }
        let degrees = real(spin, "spin")?;
        SpinSchedule::constant(degrees.to_radians()).map_err(build_err)?;
        Ok(Self::Constant(degrees.to_radians()))
    }

    pub(crate) fn state(&self) -> SpinState {
        let o = match self {
            Self::Optimize(o) => *o,
            _ => SpinOptions::default(),
        };
        let (mode, angle) = match self {
            Self::Keep => ("keep", 0.0),
            Self::Constant(a) => ("constant", *a),
            Self::Optimize(_) => ("optimize", 0.0),
        };
        (
            mode.to_string(),
            angle,
            o.step,
            o.per_metre,
            o.per_second,
            o.measure.name().to_string(),
        )
    }

    pub(crate) fn of_state(state: SpinState) -> PyResult<Self> {
        let (mode, angle, step, per_metre, per_second, measure) = state;
        let measure = SpinMeasure::from_name(&measure)
            .ok_or_else(|| InputError::new_err(format!("pickled spin measure {measure:?}")))?;
        match mode.as_str() {
            "keep" => Ok(Self::Keep),
            "constant" => {
                SpinSchedule::constant(angle).map_err(build_err)?;
                Ok(Self::Constant(angle))
            }
            "optimize" => {
                let o = SpinOptions {
                    step,
                    per_metre,
                    per_second,
                    measure,
                    ..SpinOptions::default()
                };
                o.validate().map_err(build_err)?;
                Ok(Self::Optimize(o))
            }
            other => Err(InputError::new_err(format!("pickled spin mode {other:?}"))),
        }
    }
}

/// `blending=`: `None` or `"stop"`, `"program"`, or a tolerance [m] (validated by the job).
pub(crate) fn blending(o: Option<&Bound<'_, PyAny>>) -> PyResult<Blending> {
    let Some(o) = o else {
        return Ok(Blending::ExactStop);
    };
    if let Ok(name) = o.extract::<String>() {
        return match name.as_str() {
            "stop" => Ok(Blending::ExactStop),
            "program" => Ok(Blending::Program),
            other => Err(InputError::new_err(format!(
                "blending: {other:?}; expected \"stop\", \"program\" or a tolerance in metres"
            ))),
        };
    }
    Ok(Blending::Tolerance(real(o, "blending")?))
}

/// Blending as pickled, one number: -1 an exact stop, -2 the program's, a tolerance >= 0 [m]
/// (what `Blending::validate` accepts) as itself.
pub(crate) fn blending_state(b: &Blending) -> f64 {
    match *b {
        Blending::ExactStop => -1.0,
        Blending::Program => -2.0,
        Blending::Tolerance(p) => p,
    }
}

/// The blending of a pickled number ([`blending_state`]).
pub(crate) fn of_blending_state(x: f64) -> Blending {
    if x == -1.0 {
        Blending::ExactStop
    } else if x == -2.0 {
        Blending::Program
    } else {
        Blending::Tolerance(x)
    }
}

/// A job's inertia as pickled: payload mass [kg], centre of mass [m], inertia (row-major)
/// [kg m^2], link loads.
pub(crate) type InertiaState = Option<(f64, [f64; 3], [f64; 9], bool)>;

pub(crate) fn inertia_state(i: Option<&job::Inertia>) -> InertiaState {
    i.map(|i| {
        let p = &i.payload;
        let m = p.inertia.transpose();
        let mut flat = [0.0; 9];
        flat.copy_from_slice(m.as_slice());
        (p.mass, p.com.into(), flat, i.links)
    })
}

pub(crate) fn of_inertia_state(s: InertiaState) -> Option<job::Inertia> {
    s.map(|(mass, com, i, links)| job::Inertia {
        payload: deflect_core::dalembert::serial::Payload {
            mass,
            com: Vector3::from(com),
            inertia: nalgebra::Matrix3::from_row_slice(&i),
        },
        links,
    })
}

/// A unit quaternion from pickled coordinates, bit for bit (norm checked to 1e-12).
pub(crate) fn unit(q: [f64; 4], what: &str) -> PyResult<UnitQuaternion<f64>> {
    let q = Quaternion::new(q[3], q[0], q[1], q[2]);
    let n = q.norm();
    if (n - 1.0).abs() <= 1e-12 {
        Ok(UnitQuaternion::new_unchecked(q))
    } else {
        Err(InputError::new_err(format!(
            "pickled {what}: a unit quaternion expected, norm {n}"
        )))
    }
}
