//! numpy <-> nalgebra conversions and error mapping shared by the wrappers.

use deflect_core::TickError;
use nalgebra::{Isometry3, Matrix4, Vector6};
use numpy::ndarray::Array2;
use numpy::{AllowTypeChange, PyArray2, PyArrayLike1, PyArrayLike2, PyReadonlyArray1, ToPyArray};
use pyo3::prelude::*;

use crate::{ConvergenceError, InputError, SingularError};

/// Maps a real-time status onto the exception tree.
pub fn tick_err(e: TickError) -> PyErr {
    match e {
        TickError::Singular { .. } => SingularError::new_err(e.to_string()),
        TickError::NotConverged { .. } => ConvergenceError::new_err(e.to_string()),
        _ => InputError::new_err(e.to_string()),
    }
}

/// A 1-D float array of exactly `n` entries, copied into a `Vec`.
pub fn vec_of(a: &PyReadonlyArray1<'_, f64>, what: &str, n: usize) -> PyResult<Vec<f64>> {
    let v = a.as_array();
    if v.len() != n {
        return Err(InputError::new_err(format!(
            "{what}: expected shape ({n},), got ({},)",
            v.len()
        )));
    }
    Ok(v.iter().copied().collect())
}

/// A 6-vector (wrench or pose change).
pub fn vector6(a: &PyReadonlyArray1<'_, f64>, what: &str) -> PyResult<Vector6<f64>> {
    Ok(Vector6::from_column_slice(&vec_of(a, what, 6)?))
}

/// A 4x4 homogeneous matrix as a numpy array.
pub fn iso_to_py<'py>(py: Python<'py>, t: &Isometry3<f64>) -> Bound<'py, PyArray2<f64>> {
    let m: Matrix4<f64> = t.to_homogeneous();
    Array2::from_shape_fn((4, 4), |(i, j)| m[(i, j)]).to_pyarray(py)
}

/// Rejects NaN/inf in a 6-vector.
pub fn check_finite6(v: &Vector6<f64>, what: &str) -> PyResult<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(InputError::new_err(format!("{what}[{i}] is not finite"))),
        None => Ok(()),
    }
}

/// A 1-D array-like of floats (lists accepted, converted to f64).
pub type Arr1<'py> = PyArrayLike1<'py, f64, AllowTypeChange>;
/// A 2-D array-like of floats (lists accepted, converted to f64).
pub type Arr2<'py> = PyArrayLike2<'py, f64, AllowTypeChange>;

/// A finite 1-D array of exactly `n` entries, copied into a `Vec`; errors name `what`.
pub fn finite_vec(a: &Arr1<'_>, what: &str, n: usize) -> PyResult<Vec<f64>> {
    let v = a.as_array();
    if v.len() != n {
        return Err(InputError::new_err(format!(
            "{what}: expected shape ({n},), got ({},)",
            v.len()
        )));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(InputError::new_err(format!("{what}[{i}] is not finite")));
    }
    Ok(v.to_vec())
}
