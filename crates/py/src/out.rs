//! numpy's `out=` habit (`np.add(a, b, out=c)`): a result written into the caller's own array,
//! which is returned, so a loop that calls deflect every tick allocates no result array. The
//! array must be float64, C-contiguous, writeable and exactly the result's shape: checked
//! before any work, `InputError` naming `out` otherwise (numpy would cast other dtypes; here
//! a cast would be the allocation `out=` exists to avoid, so it is refused instead).

use numpy::{PyArrayDyn, PyArrayMethods, PyReadwriteArrayDyn, PyUntypedArrayMethods, ToPyArray};
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::try_zeros;
use crate::errors::{shape_error, shape_text};

fn layout(shape: &[usize]) -> String {
    format!(
        "a writeable C-contiguous float64 array of shape {}",
        shape_text(shape)
    )
}

/// The caller's `out` as a writeable buffer of `shape` (see the module docs).
pub(crate) fn out_buffer<'py>(
    out: &Bound<'py, PyAny>,
    shape: &[usize],
) -> PyResult<PyReadwriteArrayDyn<'py, f64>> {
    let Ok(a) = out.cast::<PyArrayDyn<f64>>() else {
        let what = match out.getattr("dtype") {
            Ok(d) => format!("dtype {d}"),
            Err(_) => format!(
                "a {}",
                out.get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            ),
        };
        return Err(InputError::new_err(format!(
            "out: expected {}, got {what}",
            layout(shape)
        )));
    };
    if a.shape() != shape {
        return Err(shape_error("out", &shape_text(shape), a.shape()));
    }
    if !a.is_c_contiguous() {
        return Err(InputError::new_err(format!(
            "out: expected {}, got a non-contiguous view",
            layout(shape)
        )));
    }
    a.try_readwrite().map_err(|e| {
        InputError::new_err(format!(
            "out: expected {} (not read-only, not an input of the same call), got: {e}",
            layout(shape)
        ))
    })
}

/// The result `values` (row-major, `shape`) written into `out` and `out` returned, or a new
/// array.
pub(crate) fn emit<'py>(
    py: Python<'py>,
    values: &[f64],
    shape: &[usize],
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let Some(o) = out else {
        // Made in its shape (one copy), not as a vector reshaped through numpy's `reshape`,
        // and with a fixed number of dimensions where it can (ndarray's dynamic dimensions
        // cost more than the copy).
        let bad = |e: numpy::ndarray::ShapeError| InputError::new_err(format!("the result: {e}"));
        return Ok(match *shape {
            [_] => values.to_pyarray(py).into_any(),
            [r, c] => numpy::ndarray::ArrayView2::from_shape((r, c), values)
                .map_err(bad)?
                .to_pyarray(py)
                .into_any(),
            _ => numpy::ndarray::ArrayViewD::from_shape(shape, values)
                .map_err(bad)?
                .to_pyarray(py)
                .into_any(),
        });
    };
    let mut w = out_buffer(o, shape)?;
    match w.as_slice_mut() {
        Ok(s) if s.len() == values.len() => s.copy_from_slice(values),
        _ => return Err(shape_error("out", &shape_text(shape), &[values.len()])),
    }
    Ok(o.clone())
}

/// Runs `fill` on the result's buffer (`shape`, row-major): the caller's `out`, then returned,
/// or a new array allocated fallibly (`MemoryError` rather than an abort).
pub(crate) fn fill_into<'py>(
    py: Python<'py>,
    shape: &[usize],
    out: Option<&Bound<'py, PyAny>>,
    fill: impl FnOnce(&mut [f64]) -> PyResult<()>,
) -> PyResult<Bound<'py, PyAny>> {
    if let Some(o) = out {
        let mut w = out_buffer(o, shape)?;
        let s = w
            .as_slice_mut()
            .map_err(|e| InputError::new_err(format!("out: {e}")))?;
        fill(s)?;
        return Ok(o.clone());
    }
    let mut buf = try_zeros(shape.iter().product(), "the result")?;
    fill(&mut buf)?;
    let a = numpy::ndarray::ArrayD::from_shape_vec(shape.to_vec(), buf)
        .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
    Ok(numpy::IntoPyArray::into_pyarray(a, py).into_any())
}
