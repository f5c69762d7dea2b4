//! A URDF `<origin>` (xyz, rpy) as a transform, checked: the robot description and the
//! controller's frames read the same element.

use std::format;
use std::string::ToString;

use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use crate::error::LoadError;

/// Largest origin coordinate a loader accepts \[m\] (and rpy angle \[rad\]): 10 km. A robot is
/// metres across; larger values are typos or hostile files, and they overflow the model.
pub const MAX_ORIGIN: f64 = 1.0e4;

/// An origin `xyz` \[m\], `rpy` \[rad\] (URDF fixed-axis x-y-z) as a transform.
pub(crate) fn pose(
    xyz: &[f64; 3],
    rpy: &[f64; 3],
    element: &str,
) -> Result<Isometry3<f64>, LoadError> {
    if !xyz.iter().chain(rpy.iter()).all(|v| v.is_finite()) {
        return Err(LoadError::NonFiniteOrigin {
            element: element.to_string(),
        });
    }
    if let Some(v) = xyz.iter().chain(rpy.iter()).find(|v| v.abs() > MAX_ORIGIN) {
        return Err(LoadError::InvalidValue {
            element: element.to_string(),
            field: "origin",
            expected: format!("|xyz| and |rpy| at most {MAX_ORIGIN:e} (m, rad)"),
            got: v.to_string(),
        });
    }
    // URDF rpy is a fixed-axis x-y-z rotation: R = Rz(yaw) Ry(pitch) Rx(roll).
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    ))
}
