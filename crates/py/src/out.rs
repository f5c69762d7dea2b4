//! numpy's `out=` habit (`np.add(a, b, out=c)`): a result written into the caller's own array,
//! which is returned, so a loop that calls deflect every tick allocates no result array. The
//! array must be float64, C-contiguous, writeable and exactly the result's shape: checked
//! before any work, `InputError` naming `out` otherwise (numpy would cast other dtypes; here
//! a cast would be the allocation `out=` exists to avoid, so it is refused instead).

use numpy::{PyArrayDyn, PyArrayMethods, PyReadwriteArrayDyn, PyUntypedArrayMethods, ToPyArray};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyTuple;

use crate::InputError;
use crate::arrays::{no_memory, try_zeros};
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

/// Runs `fill` on the result's buffer (`shape`, row-major): the caller's `out`, or a new
/// array (from `numpy.empty` past [`SMALL`] values), then returned. A `MemoryError` names the
/// result when it cannot be allocated (rather than an abort).
pub(crate) fn fill_into<'py>(
    py: Python<'py>,
    shape: &[usize],
    out: Option<&Bound<'py, PyAny>>,
    fill: impl FnOnce(&mut [f64]) -> PyResult<()>,
) -> PyResult<Bound<'py, PyAny>> {
    let small = shape
        .iter()
        .try_fold(1_usize, |a, d| a.checked_mul(*d))
        .filter(|n| *n <= SMALL);
    let result = match (out, small) {
        (Some(o), _) => o.clone(),
        (None, None) => empty(py, shape)?,
        (None, Some(n)) => {
            // Below numpy's and the C allocator's reuse of large blocks: a `Vec` handed to
            // numpy is cheaper than `numpy.empty` and a registered borrow (50 ns a call).
            let mut buf = try_zeros(n, "the result")?;
            fill(&mut buf)?;
            let a = numpy::ndarray::ArrayD::from_shape_vec(shape.to_vec(), buf)
                .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
            return Ok(numpy::IntoPyArray::into_pyarray(a, py).into_any());
        }
    };
    let mut w = out_buffer(&result, shape)?;
    let s = w
        .as_slice_mut()
        .map_err(|e| InputError::new_err(format!("out: {e}")))?;
    fill(s)?;
    Ok(result)
}

/// The largest result made as a `Vec` (128 KiB, glibc's threshold for giving a freed block
/// back to the system); larger ones come from [`empty`].
const SMALL: usize = 16 * 1024;

/// A new float64 array of `shape` from `numpy.empty`, for `fill` to write every value of:
/// numpy's allocator hands back the memory of a result freed since, where a zeroed `Vec`
/// given to numpy takes fresh pages, zeroed and faulted in on one thread before the fill
/// (1.4 ns a row more for a 1e5-row map batch, `benches/peers.py`).
fn empty<'py>(py: Python<'py>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    static EMPTY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let n = shape
        .iter()
        .try_fold(1_u128, |a, d| a.checked_mul(*d as u128))
        .unwrap_or(u128::MAX);
    if n.saturating_mul(8) > isize::MAX as u128 {
        return Err(no_memory("the result", n));
    }
    let dims = PyTuple::new(py, shape)?;
    EMPTY
        .import(py, "numpy", "empty")?
        .call1((dims,))
        .map_err(|e| {
            if e.is_instance_of::<PyMemoryError>(py) {
                no_memory("the result", n)
            } else {
                e
            }
        })
}
