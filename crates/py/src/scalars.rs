//! Python scalars to Rust: reals, counts and small tuples, each refusal an `InputError`
//! naming the argument (pyo3's own extraction would raise `TypeError` or `OverflowError`
//! without the name). Values pass unchecked where the core call checks them.

use numpy::{PyArrayDescrMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyInt};

use crate::arrays::{asarray, is_real_kind, vector};
use crate::errors::{InputError, shape_error, shape_text, short, type_name};

/// A text argument as UTF-8: a `str` (`InputError` naming `what` for a string no UTF-8
/// encodes, as a lone surrogate; `TypeError` for anything else, as pyo3 raises).
pub fn text(o: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    let s = o.cast::<pyo3::types::PyString>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "{what}: expected str, got {}",
            type_name(o)
        ))
    })?;
    match s.to_str() {
        Ok(t) => Ok(t.to_owned()),
        Err(e) => Err(InputError::new_err(format!(
            "{what}: not encodable as UTF-8 ({e})"
        ))),
    }
}

/// A real scalar: a Python int or float, a numpy real scalar or 0-d array, or an object with
/// `__float__`. Complex numbers, strings, arrays and integers too large for a float are an
/// `InputError` naming `what`. NaN and infinities pass (the core call names them).
pub fn real(o: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    if let Ok(f) = o.cast::<PyFloat>() {
        return Ok(f.value());
    }
    if o.is_instance_of::<PyInt>() {
        return o.extract::<f64>().map_err(|_| {
            InputError::new_err(format!("{what} = {} is too large for a float", short(o)))
        });
    }
    let refuse = || {
        InputError::new_err(format!(
            "{what}: expected a real number, got {} {}",
            type_name(o),
            short(o)
        ))
    };
    let a = asarray(o, what).map_err(|_| refuse())?;
    if a.ndim() != 0 {
        return Err(InputError::new_err(format!(
            "{what}: expected a real number, got an array of shape {}",
            shape_text(a.shape())
        )));
    }
    match a.dtype().kind() {
        k if is_real_kind(k) => a.extract::<f64>().map_err(|_| refuse()),
        // Python objects with __float__ (fractions.Fraction, decimal.Decimal).
        b'O' => o.extract::<f64>().map_err(|_| refuse()),
        _ => Err(refuse()),
    }
}

/// [`real`], or `None` for Python's None.
pub fn opt_real(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<f64>> {
    if o.is_none() {
        Ok(None)
    } else {
        real(o, what).map(Some)
    }
}

/// A count (iterations, window, index): a Python or numpy integer >= 0. Negative and huge
/// integers, floats and anything else are an `InputError` naming `what` (pyo3 would raise
/// `OverflowError` or `TypeError`); ranges beyond that are checked by the core call.
pub fn count(o: &Bound<'_, PyAny>, what: &str) -> PyResult<usize> {
    let index = if o.is_instance_of::<PyInt>() {
        o.clone()
    } else {
        // numpy integers and other objects with __index__; floats have none.
        o.call_method0("__index__").map_err(|_| {
            InputError::new_err(format!(
                "{what}: expected a non-negative integer, got {} {}",
                type_name(o),
                short(o)
            ))
        })?
    };
    if let Ok(n) = index.extract::<usize>() {
        return Ok(n);
    }
    let negative = index.lt(0).unwrap_or(false);
    Err(InputError::new_err(if negative {
        format!(
            "{what} = {} is negative; expected an integer >= 0",
            short(&index)
        )
    } else {
        format!(
            "{what} = {} is too large; expected an integer in 0..={}",
            short(&index),
            usize::MAX
        )
    }))
}

/// [`count`], or `None` for Python's None.
pub fn opt_count(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<usize>> {
    if o.is_none() {
        Ok(None)
    } else {
        count(o, what).map(Some)
    }
}

/// A pair of reals (a tuple, list or array of 2), values unchecked.
pub fn pair(o: &Bound<'_, PyAny>, what: &str) -> PyResult<(f64, f64)> {
    match vector(o, what, 2)?.as_slice() {
        &[a, b] => Ok((a, b)),
        _ => Err(shape_error(what, "(2,)", &[])),
    }
}

/// [`pair`], or `None` for Python's None.
pub fn opt_pair(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<(f64, f64)>> {
    if o.is_none() {
        Ok(None)
    } else {
        pair(o, what).map(Some)
    }
}

/// Three reals (a tuple, list or array of 3), values unchecked.
pub fn triple(o: &Bound<'_, PyAny>, what: &str) -> PyResult<[f64; 3]> {
    match vector(o, what, 3)?.as_slice() {
        &[a, b, c] => Ok([a, b, c]),
        _ => Err(shape_error(what, "(3,)", &[])),
    }
}

/// Three reals (a tuple, list or array of 3), values unchecked; `None` for Python's None.
pub fn opt_triple(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<[f64; 3]>> {
    if o.is_none() {
        return Ok(None);
    }
    match vector(o, what, 3)?.as_slice() {
        &[a, b, c] => Ok(Some([a, b, c])),
        _ => Err(shape_error(what, "(3,)", &[])),
    }
}
