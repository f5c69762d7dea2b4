//! `deflect.SerialRobot`: the virtual-joint model of deflect-core.

use std::sync::{Mutex, MutexGuard, PoisonError};

use deflect_core::SerialRobot as CoreRobot;
use deflect_core::TickError;
use deflect_core::io;
use deflect_core::vjm::{self, Data, Vector6};
use numpy::ndarray::{Array2, ArrayView2};
use numpy::{PyArray1, PyArray2, ToPyArray};

use pyo3::prelude::*;

use crate::InputError;
use crate::args;
use crate::arrays::{batch_pair, iso_to_py, joints, matrix, pose, vector6};
use crate::batch;
use crate::errors::{load_err, tick_err};
use crate::out::{emit, fill_into};

/// A serial robot with virtual joints (VJM paper, Eq. 1-9). All arrays are SI, base frame.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct SerialRobot {
    pub(crate) inner: CoreRobot,
    /// The workspace of single calls (batches give each thread its own): allocated once,
    /// locked per call so that the class stays frozen.
    data: Mutex<Data>,
}

impl SerialRobot {
    pub(crate) fn new(inner: CoreRobot) -> Self {
        let data = Mutex::new(Data::new(&inner.model));
        Self { inner, data }
    }

    fn data(&self) -> MutexGuard<'_, Data> {
        // A poisoned lock only means another call failed mid-call; the workspace is
        // overwritten by every call.
        self.data.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

#[pymethods]
impl SerialRobot {
    /// Loads a URDF file and a stiffness TOML file; the chain runs from `base_link` (default:
    /// the URDF root) to `tip_link`.
    #[staticmethod]
    #[pyo3(signature = (urdf_path, stiffness_path, tip_link, base_link=None))]
    fn from_urdf(
        urdf_path: std::path::PathBuf,
        stiffness_path: std::path::PathBuf,
        tip_link: &str,
        base_link: Option<&str>,
    ) -> PyResult<Self> {
        let inner = io::urdf::from_path(&urdf_path, &stiffness_path, base_link, tip_link)
            .map_err(load_err)?;
        Ok(Self::new(inner))
    }

    /// Same as `from_urdf`, from the files' texts; the chain runs from `base_link` (default:
    /// the URDF root) to `tip_link`.
    #[staticmethod]
    #[pyo3(signature = (urdf, stiffness, tip_link, base_link=None))]
    fn from_strings(
        urdf: &str,
        stiffness: &str,
        tip_link: &str,
        base_link: Option<&str>,
    ) -> PyResult<Self> {
        let inner = io::urdf::from_str(urdf, stiffness, base_link, tip_link).map_err(load_err)?;
        Ok(Self::new(inner))
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

    /// Pickling (and `copy.deepcopy`): the chain's elements, names and limits as plain Python
    /// values; the copy computes bit for bit what the original does.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (crate::pickle::RobotState,))> {
        let rebuild = slf.get_type().getattr("_from_state")?;
        Ok((rebuild, (crate::pickle::robot_state(&slf.get().inner),)))
    }

    /// The robot of a pickled state (see `__reduce__`), validated like a loaded one.
    #[staticmethod]
    fn _from_state(state: crate::pickle::RobotState) -> PyResult<Self> {
        Ok(Self::new(crate::pickle::robot_of(state)?))
    }

    /// Rigid TCP pose, a (4, 4) homogeneous matrix [m]; into `out` (4, 4) if given.
    #[pyo3(signature = (q, *, out=None))]
    fn forward<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let t = vjm::forward(model, &mut self.data(), &q).map_err(tick_err)?;
        // Row-major: the transpose's column-major storage.
        emit(py, t.to_homogeneous().transpose().as_slice(), &[4, 4], out)
    }

    /// TCP deflection `[dx, dy, dz, rx, ry, rz]` [m, rad] under the TCP wrench
    /// `[Fx, Fy, Fz, Mx, My, Mz]` [N, N m], both in the base frame; into `out` (6,) if given.
    #[pyo3(signature = (q, wrench, *, out=None))]
    fn deflection<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let w = vector6(wrench, "wrench")?;
        let d =
            vjm::deflection(model, &mut self.data(), &q, &w, vjm::Load::Exact).map_err(tick_err)?;
        emit(py, d.as_slice(), &[6], out)
    }

    /// TCP deflection in static equilibrium, laid out as `deflection`: the spring moments
    /// taken in the deflected pose (the force acts at the deflected TCP, lever arms and
    /// spring axes move with the chain), each spring a conservative element, solved by
    /// Newton's method on the spring angles (at most `max_iterations`, 1..=64, until no angle
    /// changes by more than `tolerance` [rad]; `ConvergenceError` otherwise). The paper's
    /// `deflection` takes the moments in the undeformed pose; the two differ at second
    /// order in the load, about the deflection times its own angular size (0.1-1 % for
    /// millimetre deflections of a metre-size arm).
    #[pyo3(signature = (q, wrench, max_iterations=20, tolerance=1e-12))]
    fn equilibrium<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = args::count::max_iterations)] max_iterations: usize,
        #[pyo3(from_py_with = args::real::tolerance)] tolerance: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let w = vector6(wrench, "wrench")?;
        let options = vjm::EquilibriumOptions {
            max_iterations,
            tolerance,
        };
        let e = vjm::equilibrium(model, &mut self.data(), &q, &w, &options).map_err(tick_err)?;
        Ok(e.deflection.as_slice().to_pyarray(py))
    }

    /// Elastic angles `[alpha, beta, gamma]` [rad] of every virtual joint (Eq. 7), shape
    /// (n_springs, 3), in the order of `spring_names`.
    fn spring_angles<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let w = vector6(wrench, "wrench")?;
        let mut data = self.data();
        vjm::deflection(model, &mut data, &q, &w, vjm::Load::Exact).map_err(tick_err)?;
        let n = model.spring_count();
        let flat: Vec<f64> = data
            .spring_angles
            .iter()
            .take(n)
            .flatten()
            .copied()
            .collect();
        let a =
            Array2::from_shape_vec((n, 3), flat).map_err(|e| InputError::new_err(e.to_string()))?;
        Ok(a.to_pyarray(py))
    }

    /// Cartesian compliance of the linearized model, (6, 6), `[F; M] -> [dp; dr]`; into
    /// `out` (6, 6) if given.
    #[pyo3(signature = (q, *, out=None))]
    fn compliance<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let c = vjm::compliance(model, &mut self.data(), &q).map_err(tick_err)?;
        emit(py, c.transpose().as_slice(), &[6, 6], out)
    }

    /// Linearized deflection `compliance(q) @ wrench`, (6,) [m, rad], in one call (the
    /// first-order term of `deflection`); into `out` (6,) if given.
    #[pyo3(signature = (q, wrench, *, out=None))]
    fn linear_deflection<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let w = vector6(wrench, "wrench")?;
        let d = vjm::linear_deflection(model, &mut self.data(), &q, &w).map_err(tick_err)?;
        emit(py, d.as_slice(), &[6], out)
    }

    /// Actuated-joint Jacobian of the rigid TCP, (6, dof), rows `[v; w]`, base frame.
    fn joint_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let mut data = self.data();
        vjm::joint_jacobian(model, &mut data, &q).map_err(tick_err)?;
        let j = &data.jacobian;
        Ok(Array2::from_shape_fn((6, model.dof()), |ij| {
            j.get(ij).copied().unwrap_or(f64::NAN)
        })
        .to_pyarray(py))
    }

    /// Axis-specific correction `dq` (dof,) so that the robot commanded to `q + dq` under
    /// `wrench` puts its deflected TCP on the rigid TCP of `q`. `max_iterations=1` gives the
    /// first-order `-J^+ delta`; at most 256 iterations (`InputError` beyond). Raises
    /// `ConvergenceError` when the pose error left exceeds `tolerance` (finite, >= 0), also
    /// when the iteration stalled at a least-squares fixed point (an arm with fewer than 6
    /// joints rarely cancels it all: pass a looser tolerance).
    #[pyo3(signature = (q, wrench, max_iterations=10, tolerance=1e-12))]
    fn joint_correction<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        wrench: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = args::count::max_iterations)] max_iterations: usize,
        #[pyo3(from_py_with = args::real::tolerance)] tolerance: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = &self.inner.model;
        let q = joints(q, "q", model.dof())?;
        let w = vector6(wrench, "wrench")?;
        let c = vjm::joint_correction(model, &mut self.data(), &q, &w, max_iterations, tolerance)
            .map_err(tick_err)?;
        if !c.converged {
            let why = if c.stalled {
                "stalled: a step no longer lowers the residual (least-squares fixed point)"
            } else {
                "iteration budget used"
            };
            return Err(crate::ConvergenceError::new_err(format!(
                "joint correction: residual {:e} > tolerance {tolerance:e} after {} iterations \
                 ({why})",
                c.residual, c.iterations
            )));
        }
        Ok(c.dq.get(..model.dof()).unwrap_or(&[]).to_pyarray(py))
    }

    /// Deflections of many loaded poses at once: `Q` (N, dof), `W` (N, 6) -> (N, 6) [m, rad];
    /// either may be a single row ((dof,) or (6,)) that broadcasts over the other's rows, as
    /// in numpy (one pose under many wrenches, one wrench over many poses). float64
    /// C-contiguous arrays are read in place. Runs without the GIL. Into `out` (N, 6) if given.
    #[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
    #[pyo3(signature = (Q, W, *, out=None))]
    fn deflection_batch<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        W: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let dof = self.inner.model.dof();
        let (n, qm, wm) = batch_pair((Q, "Q", &[dof]), (W, "W", &[6]))?;
        let (q, w) = (qm.as_array(), wm.as_array());
        let (Some(q), Some(w)) = (q.broadcast((n, dof)), w.broadcast((n, 6))) else {
            return Err(InputError::new_err("Q and W: rows do not broadcast"));
        };
        // C-contiguous Q and W are read as rows of their slices; broadcast or strided ones
        // through ndarray's row views (several times the cost of the copy).
        let (q_rows, w_rows) = (q.as_slice(), w.as_slice());
        let model = &self.inner.model;
        let w_row = |i: usize| match w_rows.and_then(|s| s.get(6 * i..6 * i + 6)) {
            Some(r) => Vector6::from_column_slice(r),
            None => Vector6::from_iterator(w.row(i).iter().copied()),
        };
        let workspace = || (Data::new(model), [0; 4].map(|_| Vec::with_capacity(dof)));
        fill_into(py, &[n, 6], out, |buf| {
            py.detach(|| {
                batch::chunks(buf, 6, batch::row_cost::VJM, workspace, |rows, ws, o| {
                    let (data, qb) = ws;
                    // Four rows at a time in the lanes (each row's bits are the one-row
                    // path's); a group the four-row path declines, and the last rows, one
                    // at a time.
                    for (g, og) in o.chunks_mut(4 * 6).enumerate() {
                        let base = rows.start + 4 * g;
                        if og.len() == 4 * 6 {
                            let ws4 = [0, 1, 2, 3].map(|r| w_row(base + r));
                            let [b0, b1, b2, b3] = qb;
                            let q4 = [
                                batch::row_of(&q, q_rows, base, b0),
                                batch::row_of(&q, q_rows, base + 1, b1),
                                batch::row_of(&q, q_rows, base + 2, b2),
                                batch::row_of(&q, q_rows, base + 3, b3),
                            ];
                            if let Some(d4) =
                                vjm::exact_deflection_x4(model, data, q4, ws4.each_ref())
                            {
                                for (d, orow) in d4.iter().zip(og.chunks_mut(6)) {
                                    orow.copy_from_slice(d.as_slice());
                                }
                                continue;
                            }
                        }
                        for (r, orow) in og.chunks_mut(6).enumerate() {
                            let i = base + r;
                            let [b, ..] = qb;
                            let d = vjm::deflection(
                                model,
                                data,
                                batch::row_of(&q, q_rows, i, b),
                                &w_row(i),
                                vjm::Load::Exact,
                            )
                            .map_err(|e| (i, e))?;
                            orow.copy_from_slice(d.as_slice());
                        }
                    }
                    Ok(())
                })
            })
            .map_err(PyErr::from)
        })
    }

    /// Rigid TCP poses of many joint vectors: `Q` (N, dof) -> (N, 4, 4). float64
    /// C-contiguous input is read in place; runs without the GIL, on every core for large
    /// batches. Into `out` (N, 4, 4) if given.
    #[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
    #[pyo3(signature = (Q, *, out=None))]
    fn forward_batch<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qm = matrix(Q, "Q", None, Some(self.inner.model.dof()))?;
        let q = qm.as_array();
        self.per_row(py, q, &[q.nrows(), 4, 4], out, |model, data, qi, _, o| {
            let t = vjm::forward(model, data, qi)?.to_homogeneous();
            // Row-major 4 x 4: the transpose's column-major storage.
            o.copy_from_slice(t.transpose().as_slice());
            Ok(())
        })
    }

    /// Cartesian compliances of many joint vectors: `Q` (N, dof) -> (N, 6, 6), as
    /// `compliance`. float64 C-contiguous input is read in place; runs without the GIL, on
    /// every core for large batches. Into `out` (N, 6, 6) if given.
    #[allow(non_snake_case)] // reason: matrix names as in the documented Python signature
    #[pyo3(signature = (Q, *, out=None))]
    fn compliance_batch<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qm = matrix(Q, "Q", None, Some(self.inner.model.dof()))?;
        let q = qm.as_array();
        self.per_row(py, q, &[q.nrows(), 6, 6], out, |model, data, qi, _, o| {
            let c = vjm::compliance(model, data, qi)?;
            o.copy_from_slice(c.transpose().as_slice());
            Ok(())
        })
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
/// `target` (4, 4), a rigid transform (finite, bottom row 0 0 0 1, a proper rotation within
/// 1e-9: `InputError` otherwise, nothing is projected).
#[pyfunction]
fn commanded_pose<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    deflection: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let iso = pose(target, "target")?;
    let d = vector6(deflection, "deflection")?;
    let cmd = vjm::commanded_pose(&iso, &d).map_err(tick_err)?;
    Ok(iso_to_py(py, &cmd))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SerialRobot>()?;
    m.add_function(wrap_pyfunction!(commanded_pose, m)?)?;
    Ok(())
}

impl SerialRobot {
    /// The batch shape of every `*_batch` method: `row(model, data, q_i, i, out_i)` for each
    /// row `i` of `q` (N, dof; a broadcast row is read in place), `out_i` the row's
    /// `shape[1..].product()` numbers of the result of `shape`. Without the GIL, on every core
    /// for large batches ([`batch::row_cost::VJM`]); the first failing row raises as the
    /// single call would, naming the row.
    fn per_row<'py, F>(
        &self,
        py: Python<'py>,
        q: ArrayView2<'_, f64>,
        shape: &[usize],
        out: Option<&Bound<'py, PyAny>>,
        row: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&vjm::Model, &mut Data, &[f64], usize, &mut [f64]) -> Result<(), TickError> + Sync,
    {
        let model = &self.inner.model;
        let dof = model.dof();
        let width = shape.iter().skip(1).product();
        let q_rows = q.as_slice();
        fill_into(py, shape, out, |buf| {
            py.detach(|| {
                batch::rows(
                    buf,
                    width,
                    batch::row_cost::VJM,
                    || (Data::new(model), Vec::with_capacity(dof)),
                    |i, (data, qi), o| row(model, data, batch::row_of(&q, q_rows, i, qi), i, o),
                )
            })
            .map_err(PyErr::from)
        })
    }
}
