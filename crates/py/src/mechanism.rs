//! `deflect.ParallelRobot2`: the paper's 2-DoF parallel robot (Paksoy, Dede and Kiper 2025).

use deflect_core::mechanism::{Mechanism, ParallelRobot2 as CoreRobot2};
use nalgebra::Vector2;
use numpy::{PyArray1, PyArray2, ToPyArray};
use pyo3::prelude::*;

use crate::args;
use crate::arrays::{matrix_to_py, vector};
use crate::errors::{build_err, tick_err};

fn vec2(a: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector2<f64>> {
    Ok(Vector2::from_column_slice(&vector(a, what, 2)?))
}

/// The paper's 2-DoF planar parallel robot (links 150 mm, pivots 90 mm from O). Task point
/// `p = (x, y)` = C - O [m] in the static-test grid's frame; joints `q = (theta_A, theta_B)`
/// [rad], the actuated links' angles from +x; working mode "elbows out".
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct ParallelRobot2 {
    pub(crate) inner: CoreRobot2,
}

#[pymethods]
impl ParallelRobot2 {
    /// Paper geometry by default; `min_sigma` [m/rad] is the singularity threshold.
    #[new]
    #[pyo3(signature = (link=0.150, half_width=0.090, min_sigma=deflect_core::mechanism::DEFAULT_MIN_SIGMA),
           text_signature = "(link=0.15, half_width=0.09, min_sigma=0.02)")]
    fn new(
        #[pyo3(from_py_with = args::real::link)] link: f64,
        #[pyo3(from_py_with = args::real::half_width)] half_width: f64,
        #[pyo3(from_py_with = args::real::min_sigma)] min_sigma: f64,
    ) -> PyResult<Self> {
        Ok(Self {
            inner: CoreRobot2::new(link, half_width, min_sigma).map_err(build_err)?,
        })
    }
    /// Pickling (and `copy.deepcopy`): the three constructor arguments, an exact round trip.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, pyo3::types::PyType>, (f64, f64, f64))> {
        let r = &slf.get().inner;
        Ok((slf.get_type(), (r.link(), r.half_width(), r.min_sigma())))
    }
    /// Joints `q` [rad] that put C on `p` [m]; InputError out of reach, SingularError near a
    /// singularity.
    fn ik<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.inner.ik(&vec2(p, "p")?).map_err(tick_err)?;
        Ok(q.as_slice().to_pyarray(py))
    }
    /// Task point `p` [m] of joints `q` [rad].
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = self.inner.fk(&vec2(q, "q")?).map_err(tick_err)?;
        Ok(p.as_slice().to_pyarray(py))
    }
    /// Jacobian `dp/dq` [m/rad], shape (2, 2).
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let j = self.inner.jacobian_at(&vec2(q, "q")?).map_err(tick_err)?;
        Ok(matrix_to_py(py, &j))
    }
    /// Smallest singular value of the Jacobian at `q` [m/rad].
    fn singularity_distance(&self, q: &Bound<'_, PyAny>) -> PyResult<f64> {
        // The closed-form robot's workspace is `()`.
        self.inner
            .singularity_distance(&mut (), &vec2(q, "q")?)
            .map_err(tick_err)
    }
    /// Largest reach 2 L [m].
    #[getter]
    fn reach(&self) -> f64 {
        self.inner.reach()
    }
    fn __repr__(&self) -> String {
        format!(
            "ParallelRobot2(link={}, half_width={}, min_sigma={})",
            self.inner.link(),
            self.inner.half_width(),
            self.inner.min_sigma()
        )
    }
}

/// Adds the parallel robot to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ParallelRobot2>()?;
    Ok(())
}

fn vec3(a: &Bound<'_, PyAny>, what: &str) -> PyResult<nalgebra::Vector3<f64>> {
    Ok(nalgebra::Vector3::from_column_slice(&vector(a, what, 3)?))
}

/// The constructor arguments of `Delta`, as pickled.
type DeltaArgs = (f64, f64, f64, f64, f64);

/// The 3-DoF Delta robot of Clavel: base joint circle radius `base_radius`, platform joint
/// circle radius `platform_radius`, arm and forearm lengths [m]; `min_sigma` [m/rad] the
/// singularity threshold. Task point `p = (x, y, z)` [m]: the platform centre, base frame z up
/// (the platform below, z < 0); joints `q` [rad]: each arm's angle from the horizontal,
/// positive downwards; working mode "elbows out".
#[pyclass(module = "deflect", frozen, eq)]
#[derive(Debug, PartialEq)]
pub struct Delta {
    pub(crate) inner: deflect_core::mechanism::Delta,
}

#[pymethods]
impl Delta {
    #[new]
    #[pyo3(signature = (base_radius, platform_radius, arm, forearm, min_sigma=deflect_core::mechanism::DELTA_MIN_SIGMA),
           text_signature = "(base_radius, platform_radius, arm, forearm, min_sigma=0.01)")]
    fn new(
        #[pyo3(from_py_with = args::real::base_radius)] base_radius: f64,
        #[pyo3(from_py_with = args::real::platform_radius)] platform_radius: f64,
        #[pyo3(from_py_with = args::real::arm)] arm: f64,
        #[pyo3(from_py_with = args::real::forearm)] forearm: f64,
        #[pyo3(from_py_with = args::real::min_sigma)] min_sigma: f64,
    ) -> PyResult<Self> {
        let inner = deflect_core::mechanism::Delta::new(base_radius, platform_radius, arm, forearm)
            .and_then(|d| d.with_min_sigma(min_sigma))
            .map_err(build_err)?;
        Ok(Self { inner })
    }
    /// deflect's pick-and-place Delta: base radius 0.2 m, platform 0.045 m, arm 0.35 m,
    /// forearm 0.8 m.
    #[staticmethod]
    fn pick_and_place() -> Self {
        Self {
            inner: deflect_core::mechanism::Delta::pick_and_place(),
        }
    }
    /// Pickling and `copy.deepcopy`: the constructor arguments, an exact round trip.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, pyo3::types::PyType>, DeltaArgs)> {
        let d = &slf.get().inner;
        Ok((
            slf.get_type(),
            (
                d.base_radius(),
                d.platform_radius(),
                d.arm(),
                d.forearm(),
                d.min_sigma(),
            ),
        ))
    }
    /// Joints `q` (3,) [rad] that put the platform centre on `p` (3,) [m]; InputError out of
    /// reach.
    fn ik<'py>(
        &self,
        py: Python<'py>,
        p: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = self.inner.ik(&vec3(p, "p")?).map_err(tick_err)?;
        Ok(q.as_slice().to_pyarray(py))
    }
    /// Platform centre `p` (3,) [m] of joints `q` (3,) [rad] (the lower of the two
    /// assemblies); InputError when the arms cannot be assembled.
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = self.inner.fk(&vec3(q, "q")?).map_err(tick_err)?;
        Ok(p.as_slice().to_pyarray(py))
    }
    /// Jacobian `dp/dq` (3, 3) [m/rad] at `q`; SingularError below `min_sigma`.
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let j = self
            .inner
            .jacobian(&mut (), &vec3(q, "q")?)
            .map_err(tick_err)?;
        Ok(matrix_to_py(py, &j))
    }
    /// Smallest singular value of the Jacobian at `q` [m/rad].
    fn singularity_distance(&self, q: &Bound<'_, PyAny>) -> PyResult<f64> {
        self.inner
            .singularity_distance(&mut (), &vec3(q, "q")?)
            .map_err(tick_err)
    }
    /// Base joint circle radius [m].
    #[getter]
    fn base_radius(&self) -> f64 {
        self.inner.base_radius()
    }
    /// Platform joint circle radius [m].
    #[getter]
    fn platform_radius(&self) -> f64 {
        self.inner.platform_radius()
    }
    /// Arm length [m].
    #[getter]
    fn arm(&self) -> f64 {
        self.inner.arm()
    }
    /// Forearm length [m].
    #[getter]
    fn forearm(&self) -> f64 {
        self.inner.forearm()
    }
    fn __repr__(&self) -> String {
        let d = &self.inner;
        format!(
            "Delta(base_radius={}, platform_radius={}, arm={}, forearm={}, min_sigma={})",
            d.base_radius(),
            d.platform_radius(),
            d.arm(),
            d.forearm(),
            d.min_sigma()
        )
    }
}

/// Adds the Delta robot to the module.
pub fn register_delta(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Delta>()
}
