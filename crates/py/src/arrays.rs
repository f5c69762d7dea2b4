//! Python array-likes to Rust, and Rust results to numpy arrays. Arrays go through numpy
//! once: `numpy.asarray`, a dtype-kind check (bool, int, unsigned and float convert; complex,
//! object, string, datetime and void arrays are refused with an `InputError` naming the
//! argument) and one conversion to float64; float64 C-contiguous arrays are read in place.
//! Values are not checked here: the core call validates them and names what it refuses.

use deflect_core::vjm::{self, Vector6};
use nalgebra::{Isometry3, Matrix3, Matrix4, UnitQuaternion};
use numpy::ndarray::{Array, Array2, Dimension};
use numpy::{
    PyArray1, PyArray2, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArray2,
    PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods, ToPyArray,
};
use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyFloat, PyInt, PyList, PyTuple};

use crate::errors::{InputError, shape_error, shape_text, tick_err_at};

/// `numpy.asarray(o)`; a ValueError of numpy (ragged nested lists) becomes an `InputError`
/// naming `what`. numpy's own TypeErrors (an object whose `__array__` refuses) stay.
pub(crate) fn asarray<'py>(
    o: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let py = o.py();
    let f = ASARRAY.import(py, "numpy", "asarray")?;
    let a = f.call1((o,)).map_err(|e| {
        if e.is_instance_of::<PyValueError>(py) {
            InputError::new_err(format!("{what}: not an array of numbers ({e})"))
        } else {
            e
        }
    })?;
    Ok(a.cast_into::<PyUntypedArray>()?)
}

/// dtype kinds that convert to float64 with their meaning: bool, signed and unsigned
/// integers, floats.
pub(crate) fn is_real_kind(kind: u8) -> bool {
    matches!(kind, b'b' | b'i' | b'u' | b'f')
}

/// `o` as a float64 numpy array of any shape (no copy if it already is one). Complex,
/// object, string, datetime and structured arrays are refused with an `InputError` naming
/// `what`, the received dtype and shape: numpy would otherwise drop imaginary parts with a
/// warning only.
pub fn float_array<'py>(
    o: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = o.cast::<PyArrayDyn<f64>>() {
        return Ok(a.clone());
    }
    let a = asarray(o, what)?;
    let dtype = a.dtype();
    if !is_real_kind(dtype.kind()) {
        return Err(InputError::new_err(format!(
            "{what}: expected an array of real numbers (float, int or bool dtype), got dtype \
             {dtype} with shape {}",
            shape_text(a.shape())
        )));
    }
    let f = a.call_method1("astype", ("float64",))?;
    Ok(f.cast_into::<PyArrayDyn<f64>>()?)
}

/// Read access to a float64 array (refused while another thread writes to it).
fn readonly<'py, D: numpy::ndarray::Dimension>(
    a: &Bound<'py, numpy::PyArray<f64, D>>,
    what: &str,
) -> PyResult<numpy::PyReadonlyArray<'py, f64, D>> {
    a.try_readonly()
        .map_err(|e| InputError::new_err(format!("{what}: cannot be read: {e}")))
}

/// `o` as a float64 array of any shape, read-only.
pub fn array_dyn<'py>(o: &Bound<'py, PyAny>, what: &str) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    readonly(&float_array(o, what)?, what)
}

/// Longest input [`fast_vector`] reads (per-call vectors: joints, wrenches, points).
const FAST_VECTOR_MAX: usize = 64;

/// The numbers of a float64 1-D numpy array, a list or a tuple of Python floats and ints,
/// read directly (the common per-call inputs: no numpy round trip). `None` for anything
/// else, which then goes through numpy's conversion and its checks.
pub(crate) fn fast_vector(o: &Bound<'_, PyAny>) -> Option<Vec<f64>> {
    // Only short inputs: a long one goes through the checked path, whose budget comes before
    // any copy (an infallible copy of 1e8 entries here would abort the interpreter).
    if let Ok(a) = o.cast::<PyArray1<f64>>() {
        if a.len() > FAST_VECTOR_MAX {
            return None;
        }
        // `to_vec` copies under the GIL without registering a borrow: rust-numpy's borrow
        // tracking costs more than the copy of a few entries (measured ~0.2 us per array).
        return a.to_vec().ok();
    }
    let number = |x: Bound<'_, PyAny>| py_number(&x);
    if let Ok(l) = o.cast::<PyList>() {
        if l.len() > FAST_VECTOR_MAX {
            return None;
        }
        return l.iter().map(number).collect();
    }
    if let Ok(t) = o.cast::<PyTuple>() {
        if t.len() > FAST_VECTOR_MAX {
            return None;
        }
        return t.iter().map(number).collect();
    }
    None
}

/// A Python float (or subclass: numpy.float64 is one) or an exact int (not bool) as f64; `None`
/// for anything else, which then goes through numpy and its checks.
fn py_number(x: &Bound<'_, PyAny>) -> Option<f64> {
    if let Ok(f) = x.cast::<PyFloat>() {
        Some(f.value())
    } else if x.is_exact_instance_of::<PyInt>() {
        x.extract::<f64>().ok()
    } else {
        None
    }
}

/// Fills `out` from a list or tuple of exactly `out.len()` Python floats or ints without
/// allocating (the per-call inputs of a re-planning loop); else [`fast_vector`]'s float64
/// vector of that length. `false` (and `out` unspecified) for anything else, which the caller
/// then reads through numpy and its checks.
pub(crate) fn fill_fast(o: &Bound<'_, PyAny>, out: &mut [f64]) -> bool {
    fn fill<'py>(items: impl Iterator<Item = Bound<'py, PyAny>>, out: &mut [f64]) -> bool {
        for (d, x) in out.iter_mut().zip(items) {
            match py_number(&x) {
                Some(v) => *d = v,
                None => return false,
            }
        }
        true
    }
    if let Some(s) = float64_vector(o) {
        if s.len() != out.len() {
            return false;
        }
        out.copy_from_slice(s);
        return true;
    }
    if let Ok(l) = o.cast::<PyList>() {
        return l.len() == out.len() && fill(l.iter(), out);
    }
    if let Ok(t) = o.cast::<PyTuple>() {
        return t.len() == out.len() && fill(t.iter(), out);
    }
    if let Ok(a) = o.cast::<PyArray1<f64>>() {
        if a.len() != out.len() {
            return false;
        }
        if let Some(s) = contiguous(a) {
            out.copy_from_slice(s);
            return true;
        }
        // Strided: element by element, still without a Vec or a borrow registration.
        return out
            .iter_mut()
            .enumerate()
            .all(|(i, d)| a.get_owned([i]).map(|v| *d = v).is_some());
    }
    false
}

/// The numbers of a contiguous float64 vector, for [`fill_fast`] to copy at once (`None` when
/// strided): the read of rust-numpy's safe `PyArray::to_vec`, without its heap allocation.
/// A per-call input of six numbers costs less to copy than to allocate for, to register a
/// read borrow for, or to read element by element through `get_owned` (13 ns more a vector,
/// UR5 `linear_deflection` from Python).
// reason: `PyArray::as_slice` is unsafe; the SAFETY comment below says why this use is sound
#[allow(unsafe_code)]
fn contiguous<'a>(a: &'a Bound<'_, PyArray1<f64>>) -> Option<&'a [f64]> {
    // SAFETY: `as_slice` is unsafe because the slice could alias a mutable view of the same
    // memory. The only caller holds the GIL (the `Bound`) and copies the slice before it runs
    // any Python code or lets the GIL go, as rust-numpy's safe `to_vec` and `get_owned` read
    // the array: no reference to the data outlives that copy.
    unsafe { a.as_slice() }.ok()
}

/// The numbers of a plain `numpy.ndarray` (not a subclass) of one dimension, C-contiguous,
/// whose dtype is numpy's own float64 descriptor (`None` for anything else, which
/// [`fill_fast`] then reads through rust-numpy's checked cast). The per-call inputs of a
/// 2 kHz loop are almost always such arrays, and rust-numpy's cast spends about 140
/// instructions a vector on finding that out (a type-object lookup, a subtype check, a dtype
/// made and compared): here it is two pointer comparisons against values looked up once.
// reason: the cast to the array type and `as_slice` are unsafe; the SAFETY comments say why
// these uses are sound
#[allow(unsafe_code)]
fn float64_vector<'a>(o: &'a Bound<'_, PyAny>) -> Option<&'a [f64]> {
    static TYPES: PyOnceLock<(Py<PyAny>, Py<numpy::PyArrayDescr>)> = PyOnceLock::new();
    let py = o.py();
    let (ndarray, float64) = TYPES.get_or_init(py, || {
        (
            py.get_type::<PyUntypedArray>().into_any().unbind(),
            numpy::dtype::<f64>(py).unbind(),
        )
    });
    if o.get_type_ptr().cast::<pyo3::ffi::PyObject>() != ndarray.as_ptr() {
        return None;
    }
    // SAFETY: `o`'s type is exactly `numpy.ndarray`, so it is a `PyArrayObject`, whose header
    // `PyUntypedArray` reads.
    let a = unsafe { o.cast_unchecked::<PyUntypedArray>() };
    if a.ndim() != 1 || !a.dtype().is(float64) {
        return None;
    }
    // SAFETY: one dimension and numpy's float64 descriptor (native byte order) are what
    // rust-numpy's own cast to `PyArray1<f64>` checks.
    let a = unsafe { a.cast_unchecked::<PyArray1<f64>>() };
    contiguous(a)
}

/// A joint vector (at most [`vjm::MAX_DOF`] entries) on the stack: the per-call inputs of the
/// single-call methods, read without a heap allocation by [`fill_fast`] when they are a
/// float64 vector, a list or a tuple, else through [`vector`]'s checks.
#[derive(Debug, Clone, Copy)]
pub struct Joints {
    buf: [f64; vjm::MAX_DOF],
    len: usize,
}

impl core::ops::Deref for Joints {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        self.buf.get(..self.len).unwrap_or(&[])
    }
}

/// `o` as a joint vector of exactly `n` entries ([`Joints`]); errors as [`vector`].
pub fn joints(o: &Bound<'_, PyAny>, what: &str, n: usize) -> PyResult<Joints> {
    let mut j = Joints {
        buf: [0.0; vjm::MAX_DOF],
        len: n,
    };
    let Some(slot) = j.buf.get_mut(..n) else {
        // Unreachable: a model has at most MAX_DOF joints.
        return Err(shape_error(
            what,
            &format!("at most ({},)", vjm::MAX_DOF),
            &[n],
        ));
    };
    if !fill_fast(o, slot) {
        slot.copy_from_slice(&vector(o, what, n)?);
    }
    Ok(j)
}

/// A buffer of `n` zeros for a result (or a copy) whose size the caller chose, allocated
/// fallibly: `MemoryError` naming `what`, the count and the bytes when the system refuses it
/// (numpy's answer to the same request), never an abort of the interpreter. A size past
/// `isize::MAX` bytes is refused the same way.
pub fn try_zeros(n: usize, what: &str) -> PyResult<Vec<f64>> {
    let mut v = try_with_capacity(n, what)?;
    v.resize(n, 0.0);
    Ok(v)
}

/// An empty vector with room for `n` numbers, allocated fallibly (see [`try_zeros`]).
pub fn try_with_capacity(n: usize, what: &str) -> PyResult<Vec<f64>> {
    if n.checked_mul(8).is_none_or(|b| b > isize::MAX as usize) {
        return Err(no_memory(what, n as u128));
    }
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| no_memory(what, n as u128))?;
    Ok(v)
}

/// An empty vector with room for `n` values of any type (a result's rows of states or
/// poses), allocated fallibly as [`try_zeros`].
pub fn try_vec<T>(n: usize, what: &str) -> PyResult<Vec<T>> {
    let size = core::mem::size_of::<T>().max(1);
    let refused = || no_memory_bytes(what, n, (n as u128).saturating_mul(size as u128));
    if n.checked_mul(size).is_none_or(|b| b > isize::MAX as usize) {
        return Err(refused());
    }
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| refused())?;
    Ok(v)
}

/// An array of `dim` zeros (`T::default()`), allocated fallibly as [`try_zeros`]: a result
/// whose size grows with an argument (a trajectory's ticks, a batch's rows).
pub fn try_array<T: Clone + Default, D: Dimension>(dim: D, what: &str) -> PyResult<Array<T, D>> {
    let Some(n) = dim.size_checked() else {
        return Err(no_memory_bytes(what, usize::MAX, u128::MAX));
    };
    let mut v = try_vec::<T>(n, what)?;
    v.resize(n, T::default());
    Array::from_shape_vec(dim, v).map_err(|e| InputError::new_err(format!("internal: {e}")))
}

/// [`try_zeros`] for `rows` rows of `width` numbers (a batch's result).
pub fn try_rows(rows: usize, width: usize, what: &str) -> PyResult<Vec<f64>> {
    let n = rows
        .checked_mul(width)
        .ok_or_else(|| no_memory(what, rows as u128 * width as u128))?;
    try_zeros(n, what)
}

/// The `MemoryError` of a refused allocation of `n` values, `bytes` in all.
fn no_memory_bytes(what: &str, n: usize, bytes: u128) -> PyErr {
    PyMemoryError::new_err(format!(
        "{what}: cannot allocate {n} values ({bytes} bytes)"
    ))
}

/// The `MemoryError` of a refused allocation of `n` float64 numbers.
pub(crate) fn no_memory(what: &str, n: u128) -> PyErr {
    PyMemoryError::new_err(format!(
        "{what}: cannot allocate {n} float64 numbers ({} bytes)",
        n.saturating_mul(8)
    ))
}

/// The entries of `v` in row-major order, copied into a fallibly allocated vector.
pub fn try_copy<D: numpy::ndarray::Dimension>(
    v: &numpy::ndarray::ArrayView<'_, f64, D>,
    what: &str,
) -> PyResult<Vec<f64>> {
    let mut out = try_with_capacity(v.len(), what)?;
    out.extend(v.iter().copied());
    Ok(out)
}

/// `o` as a 1-D float array of at most `max` entries (the documented limit named `budget`),
/// copied; a longer one is refused with an `InputError` before anything is copied.
pub fn vector_upto(
    o: &Bound<'_, PyAny>,
    what: &str,
    max: usize,
    budget: &str,
) -> PyResult<Vec<f64>> {
    if let Some(v) = fast_vector(o) {
        check_count(what, v.len(), "entries", max, budget)?;
        return Ok(v);
    }
    let a = array_dyn(o, what)?;
    let v = a.as_array();
    if v.ndim() != 1 {
        return Err(shape_error(what, "(n,)", v.shape()));
    }
    check_count(what, v.len(), "entries", max, budget)?;
    try_copy(&v, what)
}

/// `InputError` when `n` `unit` ("entries", "rows") of `what` exceed the documented limit
/// `budget` = `max`.
pub fn check_count(what: &str, n: usize, unit: &str, max: usize, budget: &str) -> PyResult<()> {
    if n > max {
        return Err(InputError::new_err(format!(
            "{what}: {n} {unit}; the limit is {budget} = {max} {unit}"
        )));
    }
    Ok(())
}

/// `o` as a 1-D float array of exactly `n` entries, copied (no finiteness check: the core
/// call checks and names what it refuses).
pub fn vector(o: &Bound<'_, PyAny>, what: &str, n: usize) -> PyResult<Vec<f64>> {
    if let Some(v) = fast_vector(o).filter(|v| v.len() == n) {
        return Ok(v);
    }
    let a = array_dyn(o, what)?;
    let v = a.as_array();
    if v.shape() != [n] {
        return Err(shape_error(what, &format!("({n},)"), v.shape()));
    }
    Ok(v.iter().copied().collect())
}

/// A 6-vector (wrench or pose change).
pub fn vector6(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector6> {
    let mut v = [0.0; 6];
    if !fill_fast(o, &mut v) {
        v.copy_from_slice(&vector(o, what, 6)?);
    }
    Ok(Vector6::from(v))
}

/// `o` as a 2-D float array; `rows`/`cols` fix a dimension (`None`: any). The message shows
/// `N` and `M` for free dimensions.
pub fn matrix<'py>(
    o: &Bound<'py, PyAny>,
    what: &str,
    rows: Option<usize>,
    cols: Option<usize>,
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let a = float_array(o, what)?;
    let shape = a.shape().to_vec();
    let fits = match shape.as_slice() {
        [r, c] => rows.is_none_or(|n| n == *r) && cols.is_none_or(|n| n == *c),
        _ => false,
    };
    if !fits {
        let dim = |d: Option<usize>, free: &str| d.map_or(free.to_string(), |n| n.to_string());
        return Err(shape_error(
            what,
            &format!("({}, {})", dim(rows, "N"), dim(cols, "M")),
            &shape,
        ));
    }
    let a2 = a.cast_into::<PyArray2<f64>>()?;
    readonly(&a2, what)
}

/// One argument of a batch, (rows, k) with `k` one of `cols`: rows (N, k), or a single row
/// (k,) (returned as (1, k)) that numpy's broadcasting repeats for every row of the others.
fn batch_arg<'py>(
    o: &Bound<'py, PyAny>,
    what: &str,
    cols: &[usize],
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let a = float_array(o, what)?;
    let shape = a.shape().to_vec();
    let expected = || {
        let k = cols
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join(" or ");
        format!("(N, {k}) or ({k},)")
    };
    let a = match shape.as_slice() {
        [k] if cols.contains(k) => a.reshape(vec![1, *k])?,
        [_, k] if cols.contains(k) => a,
        _ => return Err(shape_error(what, &expected(), &shape)),
    };
    readonly(&a.cast_into::<PyArray2<f64>>()?, what)
}

/// Two batch arguments under numpy's broadcasting rule for the row axis: each is (N, k) or a
/// single row (k,); the row counts must be equal or one of them 1. Returns the common row
/// count. Neither array is copied here: a float64 C-contiguous argument is read in place.
pub fn batch_pair<'py>(
    a: (&Bound<'py, PyAny>, &str, &[usize]),
    b: (&Bound<'py, PyAny>, &str, &[usize]),
) -> PyResult<(
    usize,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
)> {
    let (x, y) = (batch_arg(a.0, a.1, a.2)?, batch_arg(b.0, b.1, b.2)?);
    let (nx, ny) = (x.as_array().nrows(), y.as_array().nrows());
    let n = match (nx, ny) {
        _ if nx == ny => nx,
        (_, 1) => nx,
        (1, _) => ny,
        _ => {
            return Err(InputError::new_err(format!(
                "{} has {nx} rows and {} has {ny}: batch arguments broadcast when their row \
                 counts are equal or one of them has a single row",
                a.1, b.1
            )));
        }
    };
    Ok((n, x, y))
}

/// An `R x C` matrix as a nalgebra matrix.
pub fn fixed_matrix<const R: usize, const C: usize>(
    o: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<nalgebra::SMatrix<f64, R, C>> {
    let a = matrix(o, what, Some(R), Some(C))?;
    let v = a.as_array();
    let mut m = nalgebra::SMatrix::<f64, R, C>::zeros();
    for ((i, j), x) in v.indexed_iter() {
        if let Some(dst) = m.get_mut((i, j)) {
            *dst = *x;
        }
    }
    Ok(m)
}

/// A 4x4 homogeneous transform, checked by deflect-core's [`vjm::pose_from_matrix`]:
/// finite, bottom row `0 0 0 1`, a proper rotation (no reflection, no projection).
pub fn pose(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Isometry3<f64>> {
    pose_of(&fixed_matrix::<4, 4>(o, what)?, what)
}

/// [`pose`] of a matrix already read.
pub fn pose_of(m: &Matrix4<f64>, what: &str) -> PyResult<Isometry3<f64>> {
    vjm::pose_from_matrix(m)
        .map_err(|e| tick_err_at(format_args!("{what}: not a rigid transform"), e))
}

/// A 3x3 rotation matrix, checked by deflect-core's [`vjm::rotation_from_matrix`].
pub fn rotation(o: &Bound<'_, PyAny>, what: &str) -> PyResult<UnitQuaternion<f64>> {
    rotation_of(&fixed_matrix::<3, 3>(o, what)?, what)
}

/// [`rotation`] of a matrix already read.
pub fn rotation_of(m: &Matrix3<f64>, what: &str) -> PyResult<UnitQuaternion<f64>> {
    vjm::rotation_from_matrix(m)
        .map_err(|e| tick_err_at(format_args!("{what}: not a rotation matrix"), e))
}

/// A 4x4 homogeneous matrix as a numpy array.
pub fn iso_to_py<'py>(py: Python<'py>, t: &Isometry3<f64>) -> Bound<'py, PyArray2<f64>> {
    matrix_to_py(py, &t.to_homogeneous())
}

/// Writes the 4x4 homogeneous matrix of `iso` into `arr[i]` of an (n, 4, 4) array (nothing
/// past the end).
pub fn put_pose(arr: &mut numpy::ndarray::Array3<f64>, i: usize, iso: &Isometry3<f64>) {
    if i >= arr.shape().first().copied().unwrap_or(0) {
        return;
    }
    let h = iso.to_homogeneous();
    for ((r, c), v) in arr
        .index_axis_mut(numpy::ndarray::Axis(0), i)
        .indexed_iter_mut()
    {
        if let Some(x) = h.get((r, c)) {
            *v = *x;
        }
    }
}

/// Any nalgebra matrix as a (rows, cols) numpy array.
pub fn matrix_to_py<'py, const R: usize, const C: usize>(
    py: Python<'py>,
    m: &nalgebra::SMatrix<f64, R, C>,
) -> Bound<'py, PyArray2<f64>> {
    // nalgebra stores columns; the transpose's storage is the row-major order.
    let rows: Vec<f64> = m.transpose().as_slice().to_vec();
    match Array2::from_shape_vec((R, C), rows) {
        Ok(a) => a.to_pyarray(py),
        // Unreachable (R * C entries); an empty array rather than a panic.
        Err(_) => Array2::<f64>::zeros((0, 0)).to_pyarray(py),
    }
}

/// `o` as a 1-D array of non-negative integer indices: integer arrays (and float arrays of
/// whole numbers) are accepted, anything else is an `InputError` naming `what`; more than
/// `max` entries (the limit named `budget`) are refused before any copy.
pub fn indices(o: &Bound<'_, PyAny>, what: &str, max: usize, budget: &str) -> PyResult<Vec<usize>> {
    let a = asarray(o, what)?;
    check_count(what, a.len(), "entries", max, budget)?;
    let dtype = a.dtype();
    if !matches!(dtype.kind(), b'i' | b'u' | b'f' | b'b') {
        return Err(InputError::new_err(format!(
            "{what}: expected an array of integers, got dtype {dtype} with shape {}",
            shape_text(a.shape())
        )));
    }
    if a.ndim() != 1 {
        return Err(shape_error(what, "(n,)", a.shape()));
    }
    // Through float64: exact for every index below 2^53, and anything larger is refused.
    let f = readonly(
        &a.call_method1("astype", ("float64",))?
            .cast_into::<PyArrayDyn<f64>>()?,
        what,
    )?;
    f.as_array()
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            if x.is_finite() && x >= 0.0 && x.fract() == 0.0 && x < 9.0e15 {
                // Exact: a whole number below 2^53.
                Ok(x as usize)
            } else {
                Err(InputError::new_err(format!(
                    "{what}[{i}] = {x} is not an index (an integer >= 0)"
                )))
            }
        })
        .collect()
}
