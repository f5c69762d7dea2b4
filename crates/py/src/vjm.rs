//! `deflect.SerialRobot`: the virtual-joint model of deflect-core.

use deflect_core::vjm::{self, Data, Vector6};
use deflect_core::{LoadError as CoreLoadError, SerialRobot as CoreRobot};
use numpy::ndarray::{Array1, Array2};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, ToPyArray};
use pyo3::prelude::*;

use crate::convert::{iso_to_py, tick_err, vec_of, vector6};
use crate::{InputError, LoadError};

fn load_err(e: CoreLoadError) -> PyErr {
    LoadError::new_err(e.to_string())
}

/// A serial robot with virtual joints (VJM paper, Eq. 1-9). All arrays are SI, base frame.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct SerialRobot {
    pub(crate) inner: CoreRobot,
}

#[pymethods]
impl SerialRobot {
    /// Loads a URDF file and a stiffness TOML file; the chain runs from the URDF root (or
    /// `base_link`) to `tip_link`.
    #[staticmethod]
    #[pyo3(signature = (urdf_path, stiffness_path, tip_link, base_link=None))]
    fn from_urdf(
        urdf_path: std::path::PathBuf,
        stiffness_path: std::path::PathBuf,
        tip_link: &str,
        base_link: Option<&str>,
    ) -> PyResult<Self> {
        let read = |p: &std::path::Path| {
            std::fs::read_to_string(p)
                .map_err(|e| LoadError::new_err(format!("cannot read {}: {e}", p.display())))
        };
        let urdf = read(&urdf_path)?;
        let stiffness = read(&stiffness_path)?;
        Self::from_strings(&urdf, &stiffness, tip_link, base_link)
    }

    /// Same as `from_urdf`, from the files' texts.
    #[staticmethod]
    #[pyo3(signature = (urdf, stiffness, tip_link, base_link=None))]
    fn from_strings(
        urdf: &str,
        stiffness: &str,
        tip_link: &str,
        base_link: Option<&str>,
    ) -> PyResult<Self> {
        let inner = CoreRobot::from_strs(urdf, stiffness, base_link, tip_link).map_err(load_err)?;
        Ok(Self { inner })
    }

    /// Number of actuated joints.
    #[getter]
    fn dof(&self) -> usize {
        self.inner.model.dof()
    }
    /// Actuated joint names in `q` order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joint_names.clone()
    }
    /// Joint limits `(lower, upper)` in `q` order.
    #[getter]
    fn joint_limits(&self) -> Vec<(f64, f64)> {
        self.inner.joint_limits.clone()
    }
    /// Virtual-joint labels in chain order.
    #[getter]
    fn spring_names(&self) -> Vec<String> {
        self.inner.spring_names.clone()
    }
    /// Base link of the chain.
    #[getter]
    fn base_link(&self) -> String {
        self.inner.base_link.clone()
    }
    /// Tip (TCP) link of the chain.
    #[getter]
    fn tip_link(&self) -> String {
        self.inner.tip_link.clone()
    }

    /// Rigid TCP pose, a (4, 4) homogeneous matrix [m].
    fn forward<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = &self.inner.model;
        let q = vec_of(&q, "q", model.dof())?;
        let t = vjm::forward(model, &mut Data::new(model), &q).map_err(tick_err)?;
        Ok(iso_to_py(py, &t))
    }

    /// TCP deflection `[dx, dy, dz, rx, ry, rz]` [m, rad] under the TCP wrench
    /// `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m], both in the base frame.
    fn deflection<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
        wrench: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = &self.inner.model;
        let q = vec_of(&q, "q", model.dof())?;
        let w = vector6(&wrench, "wrench")?;
        let d = vjm::deflection(model, &mut Data::new(model), &q, &w).map_err(tick_err)?;
        Ok(d.as_slice().to_pyarray(py))
    }

    /// Elastic angles `[alpha, beta, gamma]` [rad] of every virtual joint (Eq. 7), shape
    /// (n_springs, 3), in the order of `spring_names`.
    fn spring_angles<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
        wrench: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = &self.inner.model;
        let q = vec_of(&q, "q", model.dof())?;
        let w = vector6(&wrench, "wrench")?;
        let mut data = Data::new(model);
        vjm::deflection(model, &mut data, &q, &w).map_err(tick_err)?;
        let n = model.spring_count();
        Ok(Array2::from_shape_fn((n, 3), |(i, j)| data.spring_angles[i][j]).to_pyarray(py))
    }

    /// Cartesian compliance of the linearized model, (6, 6), `[F; M] -> [dp; dr]`.
    fn compliance<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = &self.inner.model;
        let q = vec_of(&q, "q", model.dof())?;
        let c = vjm::compliance(model, &mut Data::new(model), &q).map_err(tick_err)?;
        Ok(Array2::from_shape_fn((6, 6), |(i, j)| c[(i, j)]).to_pyarray(py))
    }

    /// Actuated-joint Jacobian of the rigid TCP, (6, dof), rows `[v; w]`, base frame.
    fn joint_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = &self.inner.model;
        let q = vec_of(&q, "q", model.dof())?;
        let mut data = Data::new(model);
        vjm::joint_jacobian(model, &mut data, &q).map_err(tick_err)?;
        Ok(Array2::from_shape_fn((6, model.dof()), |(i, j)| data.jacobian[(i, j)]).to_pyarray(py))
    }

    /// Axis-specific correction `dq` (dof,) so that the robot commanded to `q + dq` under
    /// `wrench` puts its deflected TCP on the rigid TCP of `q`. `max_iterations=1` gives the
    /// first-order `-J^+ delta`. Raises `ConvergenceError` when the pose error left exceeds
    /// `tolerance` (an arm with fewer than 6 joints rarely cancels it all: pass a looser one).
    #[pyo3(signature = (q, wrench, max_iterations=10, tolerance=1e-12))]
    fn joint_correction<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray1<'py, f64>,
        wrench: PyReadonlyArray1<'py, f64>,
        max_iterations: usize,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = &self.inner.model;
        let q = vec_of(&q, "q", model.dof())?;
        let w = vector6(&wrench, "wrench")?;
        let c = vjm::joint_correction(
            model,
            &mut Data::new(model),
            &q,
            &w,
            max_iterations,
            tolerance,
        )
        .map_err(tick_err)?;
        if !c.converged {
            return Err(crate::ConvergenceError::new_err(format!(
                "joint correction: residual {:e} > tolerance {tolerance:e} after {} iterations",
                c.residual, c.iterations
            )));
        }
        Ok(c.dq.get(..model.dof()).unwrap_or(&[]).to_pyarray(py))
    }

    /// Deflections of many loaded poses at once: `Q` (N, dof), `W` (N, 6) -> (N, 6). Runs
    /// without the GIL.
    #[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
    fn deflection_batch<'py>(
        &self,
        py: Python<'py>,
        Q: PyReadonlyArray2<'py, f64>,
        W: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = &self.inner.model;
        let (q, w) = (Q.as_array(), W.as_array());
        let n = q.nrows();
        if q.ncols() != model.dof() {
            return Err(InputError::new_err(format!(
                "Q: expected shape (N, {}), got {:?}",
                model.dof(),
                q.shape()
            )));
        }
        if w.shape() != [n, 6] {
            return Err(InputError::new_err(format!(
                "W: expected shape ({n}, 6), got {:?}",
                w.shape()
            )));
        }
        let out = py.detach(|| -> Result<Array2<f64>, String> {
            let mut data = Data::new(model);
            let mut out = Array2::zeros((n, 6));
            let mut qi = vec![0.0; model.dof()];
            for (i, (qrow, wrow)) in q.rows().into_iter().zip(w.rows()).enumerate() {
                qi.iter_mut().zip(qrow.iter()).for_each(|(d, s)| *d = *s);
                let wi = Vector6::from_iterator(wrow.iter().copied());
                let d = vjm::deflection(model, &mut data, &qi, &wi)
                    .map_err(|e| format!("row {i}: {e}"))?;
                out.row_mut(i).assign(&Array1::from_iter(d.iter().copied()));
            }
            Ok(out)
        });
        Ok(out.map_err(InputError::new_err)?.to_pyarray(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "SerialRobot(base_link='{}', tip_link='{}', dof={}, springs={})",
            self.inner.base_link,
            self.inner.tip_link,
            self.inner.model.dof(),
            self.inner.model.spring_count()
        )
    }
}

/// The pose to command, (4, 4), so that a TCP deflecting by `deflection` (6,) lands on
/// `target` (4, 4).
#[pyfunction]
fn commanded_pose<'py>(
    py: Python<'py>,
    target: PyReadonlyArray2<'py, f64>,
    deflection: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let t = target.as_array();
    if t.shape() != [4, 4] {
        return Err(InputError::new_err(format!(
            "target: expected shape (4, 4), got {:?}",
            t.shape()
        )));
    }
    if t.iter().any(|v| !v.is_finite()) {
        return Err(InputError::new_err("target: not finite"));
    }
    let m = nalgebra::Matrix4::from_fn(|i, j| t[(i, j)]);
    let rot = nalgebra::Rotation3::from_matrix(&m.fixed_view::<3, 3>(0, 0).into_owned());
    let iso = nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]),
        nalgebra::UnitQuaternion::from_rotation_matrix(&rot),
    );
    let d = vector6(&deflection, "deflection")?;
    crate::convert::check_finite6(&d, "deflection")?;
    Ok(iso_to_py(py, &vjm::commanded_pose(&iso, &d)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SerialRobot>()?;
    m.add_function(wrap_pyfunction!(commanded_pose, m)?)?;
    Ok(())
}
