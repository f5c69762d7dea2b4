//! Pickling of the model classes: each reduces to a plain-Python state (floats, strings,
//! lists) that rebuilds the same core model bit for bit, validated by deflect-core on the way
//! back (a tampered state is an `InputError`, never a model the builders would refuse).

use deflect_core::SerialRobot as CoreRobot;
use deflect_core::compensation::SensorCalibration;
use deflect_core::compensation::sensor::POLY_TERMS;
use deflect_core::controller::{Convention, Vendor};
use deflect_core::vjm::{Element, Model, ModelBuilder};
use nalgebra::{Isometry3, Matrix3, Quaternion, Translation3, Unit, UnitQuaternion, Vector3};
use pyo3::prelude::*;

use crate::InputError;
use crate::errors::build_err;

/// Version of the state layout below.
const VERSION: u32 = 2;

/// One chain element: its kind and its numbers (see [`element_state`]).
pub type ElementState = (String, Vec<f64>);

/// A controller convention: `(vendor, sign, offset, base, tool)`, frames as translation and
/// quaternion (x, y, z, w).
pub type ControllerState = (String, Vec<f64>, Vec<f64>, [f64; 7], [f64; 7]);

/// `(version, elements, joint_names, joint_limits, spring_names, base_link, tip_link,
/// controller)`.
pub type RobotState = (
    u32,
    Vec<ElementState>,
    Vec<String>,
    Vec<(f64, f64)>,
    Vec<String>,
    String,
    String,
    Option<ControllerState>,
);

fn iso(t: &Isometry3<f64>) -> [f64; 7] {
    let (p, q) = (t.translation.vector, t.rotation.coords);
    [p.x, p.y, p.z, q.x, q.y, q.z, q.w]
}

fn iso_of(v: &[f64]) -> Isometry3<f64> {
    let at = |k: usize| v.get(k).copied().unwrap_or(f64::NAN);
    Isometry3::from_parts(
        Translation3::new(at(0), at(1), at(2)),
        UnitQuaternion::new_unchecked(Quaternion::new(at(6), at(3), at(4), at(5))),
    )
}

/// `fixed`: translation, quaternion (x, y, z, w); `revolute` / `prismatic`: unit axis;
/// `spring`: compliances, frame translation, frame quaternion; `mass`: mass, centre of mass,
/// inertia row-major.
fn element_state(e: &Element) -> ElementState {
    match e {
        Element::Fixed(t) => ("fixed".into(), iso(t).to_vec()),
        Element::Revolute { axis, .. } => ("revolute".into(), axis.as_slice().to_vec()),
        Element::Prismatic { axis, .. } => ("prismatic".into(), axis.as_slice().to_vec()),
        Element::Spring {
            compliance, offset, ..
        } => {
            let mut v = compliance.as_slice().to_vec();
            v.extend_from_slice(&iso(offset));
            ("spring".into(), v)
        }
        Element::Mass {
            mass, com, inertia, ..
        } => {
            let mut v = vec![*mass];
            v.extend_from_slice(com.as_slice());
            v.extend(inertia.transpose().iter().copied());
            ("mass".into(), v)
        }
    }
}

fn element_of(k: usize, (kind, v): &ElementState) -> PyResult<Element> {
    let want = match kind.as_str() {
        "fixed" => 7,
        "revolute" | "prismatic" => 3,
        "spring" => 10,
        "mass" => 13,
        other => {
            return Err(InputError::new_err(format!(
                "pickled model: element {k} is '{other}': expected fixed, revolute, \
                 prismatic, spring or mass"
            )));
        }
    };
    if v.len() != want {
        return Err(InputError::new_err(format!(
            "pickled model: element {k} ('{kind}') has {} numbers: expected {want}",
            v.len()
        )));
    }
    let at = |i: usize| v.get(i).copied().unwrap_or(f64::NAN);
    let vec3 = |i: usize| Vector3::new(at(i), at(i + 1), at(i + 2));
    Ok(match kind.as_str() {
        "fixed" => Element::Fixed(iso_of(v)),
        "revolute" => Element::Revolute {
            axis: Unit::new_unchecked(vec3(0)),
            index: 0,
        },
        "prismatic" => Element::Prismatic {
            axis: Unit::new_unchecked(vec3(0)),
            index: 0,
        },
        "spring" => Element::Spring {
            compliance: vec3(0),
            index: 0,
            offset: iso_of(v.get(3..).unwrap_or(&[])),
        },
        _ => Element::Mass {
            mass: at(0),
            com: vec3(1),
            inertia: Matrix3::from_row_slice(v.get(4..).unwrap_or(&[])),
            index: 0,
        },
    })
}

/// The state of a chain's elements.
pub fn model_state(model: &Model) -> Vec<ElementState> {
    model.elements().iter().map(element_state).collect()
}

/// The chain of `elements`, validated by deflect-core (`ModelBuilder::element`).
pub fn model_of(elements: &[ElementState]) -> PyResult<Model> {
    let mut b = ModelBuilder::new();
    for (k, e) in elements.iter().enumerate() {
        b = b.element(element_of(k, e)?).map_err(build_err)?;
    }
    b.build().map_err(build_err)
}

/// The pickled state of a serial robot.
pub fn robot_state(r: &CoreRobot) -> RobotState {
    (
        VERSION,
        model_state(&r.model),
        r.joint_names.clone(),
        r.joint_limits.clone(),
        r.spring_names.clone(),
        r.base_link.clone(),
        r.tip_link.clone(),
        r.controller.as_ref().map(|c| {
            (
                c.vendor.name().to_string(),
                c.sign.iter().take(c.dof).copied().collect(),
                c.offset.iter().take(c.dof).copied().collect(),
                iso(&c.base),
                iso(&c.tool),
            )
        }),
    )
}

/// The serial robot of a pickled state.
pub fn robot_of(state: RobotState) -> PyResult<CoreRobot> {
    let (
        version,
        elements,
        joint_names,
        joint_limits,
        spring_names,
        base_link,
        tip_link,
        controller,
    ) = state;
    if version != VERSION {
        return Err(InputError::new_err(format!(
            "pickled SerialRobot: state version {version}; this deflect reads version {VERSION}"
        )));
    }
    let model = model_of(&elements)?;
    let (dof, springs) = (model.dof(), model.spring_count());
    if joint_names.len() != dof || joint_limits.len() != dof || spring_names.len() != springs {
        return Err(InputError::new_err(format!(
            "pickled SerialRobot: {} joint names, {} joint limits, {} spring names for a chain \
             of {dof} joints and {springs} springs",
            joint_names.len(),
            joint_limits.len(),
            spring_names.len()
        )));
    }
    if let Some(k) = joint_limits
        .iter()
        .position(|(lo, hi)| lo.is_nan() || hi.is_nan() || lo > hi)
    {
        return Err(InputError::new_err(format!(
            "pickled SerialRobot: joint limits {k} are not lower <= upper"
        )));
    }
    let controller = match controller {
        None => None,
        Some((vendor, sign, offset, base, tool)) => {
            let vendor = Vendor::from_name(&vendor).ok_or_else(|| {
                InputError::new_err(format!("pickled SerialRobot: controller vendor {vendor:?}"))
            })?;
            Some(
                Convention::new(vendor, &model, &sign, &offset, iso_of(&base), iso_of(&tool))
                    .map_err(build_err)?,
            )
        }
    };
    Ok(CoreRobot {
        model,
        joint_names,
        joint_limits,
        spring_names,
        base_link,
        tip_link,
        controller,
    })
}

/// The `TypeError` of `pickle.dumps` on an object with per-tick state.
pub(crate) fn per_tick_state(class: &str, what: &str) -> PyErr {
    pyo3::exceptions::PyTypeError::new_err(format!(
        "cannot pickle a {class}: it carries {what} from tick to tick; pickle or send its \
         constructor arguments and build a new {class} where it runs (copy.deepcopy copies \
         it with its state within one process)"
    ))
}

/// `(force_offset, moment_offset, weight, center_of_gravity, residual (6 x 15, row-major),
/// TCP translation, TCP quaternion (x, y, z, w))` of a sensor calibration.
pub type CalibrationState = (
    [f64; 3],
    [f64; 3],
    f64,
    [f64; 3],
    Vec<f64>,
    [f64; 3],
    [f64; 4],
);

/// The pickled state of a sensor calibration.
pub fn calibration_state(c: &SensorCalibration) -> CalibrationState {
    let t = iso(&c.sensor_to_tcp);
    let v3 = |v: &Vector3<f64>| [v.x, v.y, v.z];
    (
        v3(&c.force_offset),
        v3(&c.moment_offset),
        c.weight,
        v3(&c.center_of_gravity),
        c.residual.iter().flatten().copied().collect(),
        [t[0], t[1], t[2]],
        [t[3], t[4], t[5], t[6]],
    )
}

/// The sensor calibration of a pickled state, validated by deflect-core (and its quaternion
/// checked to be a unit one).
pub fn calibration_of(state: CalibrationState) -> PyResult<SensorCalibration> {
    let (f, m, weight, cog, residual, p, q) = state;
    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(norm - 1.0).abs().le(&1e-12) {
        return Err(InputError::new_err(format!(
            "pickled SensorCalibration: the TCP quaternion has norm {norm}, expected 1"
        )));
    }
    if residual.len() != 6 * POLY_TERMS {
        return Err(InputError::new_err(format!(
            "pickled SensorCalibration: residual has {} numbers, expected {}",
            residual.len(),
            6 * POLY_TERMS
        )));
    }
    let mut c = SensorCalibration {
        force_offset: Vector3::from(f),
        moment_offset: Vector3::from(m),
        weight,
        center_of_gravity: Vector3::from(cog),
        sensor_to_tcp: iso_of(&[p[0], p[1], p[2], q[0], q[1], q[2], q[3]]),
        ..SensorCalibration::default()
    };
    for (row, src) in c.residual.iter_mut().zip(residual.chunks(POLY_TERMS)) {
        row.copy_from_slice(src);
    }
    c.validate().map_err(build_err)?;
    Ok(c)
}
