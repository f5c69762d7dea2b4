//! `DisplacementField`: a compliance map evaluated once at a fixed load.

use deflect_core::compliance_map::{self as cm, DisplacementField as CoreField, MAX_AXES};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, ToPyArray};
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::{matrix, try_rows, vector_upto};
use crate::batch;
use crate::errors::{shape_error, tick_err};

/// What a pickled field is rebuilt from: its map (a `ComplianceMap`) and its load.
type FieldState = (Py<PyAny>, Vec<f64>);

/// The displacement field of a `ComplianceMap` under one fixed load
/// (`ComplianceMap.field(force)`): the node displacements (Eq. 9-10 of Paksoy, Dede and
/// Kiper 2025) computed once, so queries take a position only and blend them with the map's
/// options. Equals `map.displacement(position, force)`.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct DisplacementField {
    inner: CoreField,
    /// The `ComplianceMap` the field was computed from (held as the Python object, so this
    /// module does not depend on the map's).
    map: Py<PyAny>,
}

impl DisplacementField {
    /// The field `inner` of the Python `ComplianceMap` `map`, for `ComplianceMap.field`.
    pub(crate) fn new(map: &Bound<'_, PyAny>, inner: CoreField) -> Self {
        Self {
            inner,
            map: map.clone().unbind(),
        }
    }
}

#[pymethods]
impl DisplacementField {
    /// Displacement (n_displacement,) [m] at `position` (x, y) [m] (a 3rd entry is ignored).
    fn displacement<'py>(
        &self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = cm::planar_position(&vector_upto(position, "position", 3, "3 coordinates")?)
            .map_err(tick_err)?;
        let mut buf = [0.0; MAX_AXES];
        let out = buf
            .get_mut(..self.inner.n_displacement())
            .unwrap_or(&mut []);
        self.inner.displacement(p, out).map_err(tick_err)?;
        Ok(PyArray1::from_slice(py, out))
    }

    /// Displacements (N, n_displacement) [m] at positions `P` (N, 2) or (N, 3) [m]; float64
    /// C-contiguous input is read in place; runs without the GIL, on every core for large
    /// batches.
    #[allow(non_snake_case)] // reason: matrix name as in the documented Python signature
    fn displacement_batch<'py>(
        &self,
        py: Python<'py>,
        P: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let pm = matrix(P, "P", None, None)?;
        let p = pm.as_array();
        let (n, pc) = p.dim();
        if pc != 2 && pc != 3 {
            return Err(shape_error("P", "(N, 2) or (N, 3)", &[n, pc]));
        }
        let nd = self.inner.n_displacement();
        let field = &self.inner;
        let mut out = try_rows(n, nd, "the batch's result")?;
        py.detach(|| {
            batch::chunks(
                &mut out,
                nd,
                batch::row_cost::MAP_QUERY,
                Vec::new,
                |rows, pb, o| {
                    // Block by block: a C-contiguous `P` is read in place, a broadcast or
                    // strided one copied a block at a time.
                    let first = rows.start;
                    for b in batch::blocks(rows) {
                        let pr = batch::block(&p, b.clone(), pb);
                        let ob = o
                            .get_mut((b.start - first) * nd..(b.end - first) * nd)
                            .unwrap_or_default();
                        field
                            .displacement_batch(pr, pc, ob, field.options())
                            .map_err(|e| (b.start + e.row, e.error))?;
                    }
                    Ok(())
                },
            )
        })?;
        let a =
            Array2::from_shape_vec((n, nd), out).map_err(|e| InputError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }

    /// The load (n_force,) [N] the field was computed for.
    #[getter]
    fn force<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.force().to_pyarray(py)
    }

    /// Node displacements (nx, ny, n_displacement) [m] under the load.
    #[getter]
    fn node_values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let shape = (
            self.inner.x().len(),
            self.inner.y().len(),
            self.inner.n_displacement(),
        );
        let a = numpy::ndarray::Array3::from_shape_vec(shape, self.inner.node_values().to_vec())
            .map_err(|e| InputError::new_err(e.to_string()))?;
        Ok(a.into_pyarray(py).into_any())
    }

    /// The map the field was computed from.
    #[getter]
    fn map(&self, py: Python<'_>) -> Py<PyAny> {
        self.map.clone_ref(py)
    }

    /// Pickling: rebuilt as `map.field(force)` (an exact round trip).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, FieldState)> {
        let rebuild = self.map.bind(py).get_type().getattr("field")?;
        Ok((
            rebuild,
            (self.map.clone_ref(py), self.inner.force().to_vec()),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "DisplacementField(grid={}x{}, n_displacement={}, force={:?})",
            self.inner.x().len(),
            self.inner.y().len(),
            self.inner.n_displacement(),
            self.inner.force()
        )
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<DisplacementField>()?;
    Ok(())
}
