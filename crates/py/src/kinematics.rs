//! A five-axis machine's rotary axes from a Python dict (deflect-core's
//! `machining::Kinematics`, which checks them).

use deflect_core::machining::Kinematics;
use deflect_core::machining::kinematics::{Carrier, Rotary, RotaryWord};
use nalgebra::Vector3;
use pyo3::prelude::*;
use pyo3::types::{PyAnyMethods, PyDict};

use crate::InputError;
use crate::arrays::vector;
use crate::errors::build_err;

/// `{"tcp": bool, "rotaries": [rotary, rotary]}`, each rotary `{"word": "A" | "B" | "C",
/// "carrier": "table" | "head", "direction": (3,), "point": (3,) [m], "limits": (lower,
/// upper) [rad]}` (`point` default the origin, `limits` default +-2 pi).
pub fn kinematics(o: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Kinematics>> {
    let Some(o) = o else { return Ok(None) };
    let d = o.cast::<PyDict>().map_err(|_| {
        InputError::new_err("kinematics: expected a dict {\"tcp\": bool, \"rotaries\": [...]}")
    })?;
    let tcp = match d.get_item("tcp")? {
        Some(v) => v.extract::<bool>()?,
        None => {
            return Err(InputError::new_err(
                "kinematics: \"tcp\" (bool) is required",
            ));
        }
    };
    let Some(list) = d.get_item("rotaries")? else {
        return Err(InputError::new_err(
            "kinematics: \"rotaries\" (two dicts) is required",
        ));
    };
    let items: Vec<Bound<'_, PyAny>> = list.try_iter()?.collect::<PyResult<_>>()?;
    let [a, b] = items.as_slice() else {
        return Err(InputError::new_err(format!(
            "kinematics: \"rotaries\" must hold two rotary axes, got {}",
            items.len()
        )));
    };
    let k = Kinematics::new([rotary(a)?, rotary(b)?], tcp).map_err(build_err)?;
    Ok(Some(k))
}

fn rotary(o: &Bound<'_, PyAny>) -> PyResult<Rotary> {
    let d = o
        .cast::<PyDict>()
        .map_err(|_| InputError::new_err("kinematics: each rotary axis is a dict"))?;
    let text = |key: &str| -> PyResult<String> {
        d.get_item(key)?
            .ok_or_else(|| InputError::new_err(format!("kinematics rotary: {key:?} is required")))?
            .extract::<String>()
    };
    let word = match text("word")?.to_ascii_uppercase().as_str() {
        "A" => RotaryWord::A,
        "B" => RotaryWord::B,
        "C" => RotaryWord::C,
        other => {
            return Err(InputError::new_err(format!(
                "kinematics rotary: word must be \"A\", \"B\" or \"C\", got {other:?}"
            )));
        }
    };
    let carrier = match text("carrier")?.as_str() {
        "table" => Carrier::Table,
        "head" => Carrier::Head,
        other => {
            return Err(InputError::new_err(format!(
                "kinematics rotary: carrier must be \"table\" or \"head\", got {other:?}"
            )));
        }
    };
    let three = |key: &str, default: Option<[f64; 3]>| -> PyResult<Vector3<f64>> {
        match (d.get_item(key)?, default) {
            (Some(v), _) => Ok(Vector3::from_column_slice(&vector(&v, key, 3)?)),
            (None, Some(v)) => Ok(Vector3::from(v)),
            (None, None) => Err(InputError::new_err(format!(
                "kinematics rotary: {key:?} is required"
            ))),
        }
    };
    let tau = std::f64::consts::TAU;
    let limits = match d.get_item("limits")? {
        Some(v) => {
            let l = vector(&v, "limits", 2)?;
            (
                l.first().copied().unwrap_or(f64::NAN),
                l.get(1).copied().unwrap_or(f64::NAN),
            )
        }
        None => (-tau, tau),
    };
    Ok(Rotary {
        word,
        carrier,
        direction: three("direction", None)?,
        point: three("point", Some([0.0; 3]))?,
        limits,
    })
}
