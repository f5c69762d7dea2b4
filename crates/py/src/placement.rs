//! Where to put the workpiece (deflect-core's `machining::placement`): `PlacementProblem`
//! (the job, the program's nominal loads computed once, the seed, the job's spin setting)
//! and its search over a box. Thin: the scores and the search are core's; the Python wrapper
//! `deflect.place` hands the batches to an executor (Dask, Ray) or to every local core.

use deflect_core::machining::placement::{self, PlacementBox, Problem, Score};
use deflect_core::machining::spin::{LoadPath, SpinOptions};

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::InputError;
use crate::arrays::{matrix, vector};
use crate::errors::{build_err, job_err};
use crate::job_args::Spin;
use crate::machining::GcodeProgram;
use crate::machining_job::MachiningJob;

/// A placement search's problem: a `MachiningJob` (its arm, tool, stock and spin setting:
/// `spin="keep"` scores each placement with the seed's spin, `spin="optimize"` with the
/// spin search along the program), a `GcodeProgram` and the seed joints near its first pose.
/// The program's nominal forces are computed once here; each placement then costs the IK and
/// compliance along the program. Pickles (to a worker) with its loads as bytes.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct PlacementProblem {
    inner: Problem,
    job: Py<MachiningJob>,
}

fn spin_of(job: &MachiningJob) -> PyResult<(SpinOptions, bool)> {
    match job.spin() {
        Spin::Keep => Ok((SpinOptions::default(), false)),
        Spin::Optimize(o) => Ok((o, true)),
        Spin::Constant(_) => Err(InputError::new_err(
            "PlacementProblem: the job's spin is a constant angle; search with spin=\"keep\" \
             (turn tool_orientation instead) or spin=\"optimize\"",
        )),
    }
}

/// Scores as rows (rms [m], max [m], line).
fn score_rows<'py>(py: Python<'py>, scores: &[Score]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows: Vec<f64> = scores
        .iter()
        .flat_map(|s| [s.rms, s.max, s.line as f64])
        .collect();
    let a = Array2::from_shape_vec((scores.len(), 3), rows)
        .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// The first `N` entries of a row (0 past its end).
fn first<const N: usize>(row: impl IntoIterator<Item = f64>) -> [f64; N] {
    let mut out = [0.0; N];
    for (d, v) in out.iter_mut().zip(row) {
        *d = v;
    }
    out
}

fn params_of(o: &Bound<'_, PyAny>) -> PyResult<Vec<[f64; 4]>> {
    let m = matrix(o, "params", None, Some(4))?;
    let a = m.as_array();
    Ok(a.rows()
        .into_iter()
        .map(|r| first(r.iter().copied()))
        .collect())
}

/// A pickled problem: the job, the loads' bytes, the seed.
type State<'py> = (Py<MachiningJob>, Bound<'py, PyBytes>, Vec<f64>);

/// The local thread count (all cores) when `threads` is None.
fn thread_count(threads: Option<usize>) -> PyResult<usize> {
    match threads {
        Some(0) => Err(InputError::new_err(
            "threads: expected >= 1 (None: every core)",
        )),
        Some(n) => Ok(n.min(256)),
        None => Ok(std::thread::available_parallelism().map_or(1, |n| n.get())),
    }
}

#[pymethods]
impl PlacementProblem {
    #[new]
    fn new(
        py: Python<'_>,
        job: Bound<'_, MachiningJob>,
        program: &GcodeProgram,
        seed: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let (spin, optimise) = spin_of(job.get())?;
        let core = job.get().job().clone();
        let seed = vector(seed, "seed", core.model().dof())?;
        let program = program.inner.clone();
        let inner = py
            .detach(|| Problem::new(core, &program, &seed, spin, optimise))
            .map_err(job_err)?;
        Ok(Self {
            inner,
            job: job.unbind(),
        })
    }

    /// The scores of placements `params` (m, 4): x, y, z [m] of the workpiece origin in the
    /// base frame, yaw [rad] about the base's vertical (the job's placement's rotation turned
    /// by it). Rows (m, 3): RMS and largest predicted deflection [m] (inf where the arm cannot
    /// follow the program) and the program line where it cannot (0). On `threads` threads
    /// (None: every core), the GIL released; the result does not depend on the count.
    #[pyo3(signature = (params, threads=None))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        params: &Bound<'py, PyAny>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p = params_of(params)?;
        let threads = thread_count(threads)?;
        let scores = py.detach(|| self.inner.evaluate_all(&p, threads));
        score_rows(py, &scores)
    }

    /// The workpiece frame (4, 4) of one placement (x, y, z, yaw).
    fn placement<'py>(
        &self,
        py: Python<'py>,
        params: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v = vector(params, "params", 4)?;
        let h = self.inner.placement(&first(v)).to_homogeneous();
        let a = Array2::from_shape_fn((4, 4), |(r, c)| h.get((r, c)).copied().unwrap_or(0.0));
        Ok(a.into_pyarray(py))
    }

    /// The search (deflect-core's `placement::search`): the grid of `steps` (4,) points over
    /// `[box_min, box_max]` (4,) each, `refine` compass rounds; each batch scored by
    /// `evaluate(params (m, 4)) -> (m, 3)` (None: `self.evaluate` on every core). Returns
    /// (grid params (N, 4), grid scores (N, 3), best params (4,), best score (3,),
    /// evaluations).
    #[pyo3(signature = (box_min, box_max, steps, refine, evaluate=None))]
    #[allow(clippy::type_complexity)]
    fn _search<'py>(
        &self,
        py: Python<'py>,
        box_min: &Bound<'py, PyAny>,
        box_max: &Bound<'py, PyAny>,
        steps: [usize; 4],
        refine: usize,
        evaluate: Option<Bound<'py, PyAny>>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        usize,
    )> {
        let (lo, hi) = (
            vector(box_min, "box_min", 4)?,
            vector(box_max, "box_max", 4)?,
        );
        let bx = PlacementBox {
            min: first(lo),
            max: first(hi),
            steps,
        };
        let threads = thread_count(None)?;
        let run = |ps: &[[f64; 4]]| -> PyResult<Vec<Score>> {
            let Some(f) = &evaluate else {
                return Ok(py.detach(|| self.inner.evaluate_all(ps, threads)));
            };
            let rows: Vec<f64> = ps.iter().flatten().copied().collect();
            let arg = Array2::from_shape_vec((ps.len(), 4), rows)
                .map_err(|e| InputError::new_err(format!("internal: {e}")))?
                .into_pyarray(py);
            let out = f.call1((arg,))?;
            let m = matrix(&out, "evaluate's result", Some(ps.len()), Some(3))?;
            let a = m.as_array();
            Ok(a.rows()
                .into_iter()
                .map(|r| {
                    let [rms, max, line] = first(r.iter().copied());
                    Score {
                        rms,
                        max,
                        line: line.max(0.0) as usize,
                    }
                })
                .collect())
        };
        let found = placement::search(&bx, refine, run)?.map_err(build_err)?;
        let params: Vec<f64> = found.grid.iter().flat_map(|(p, _)| *p).collect();
        let scores: Vec<Score> = found.grid.iter().map(|(_, s)| *s).collect();
        let grid = Array2::from_shape_vec((found.grid.len(), 4), params)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?
            .into_pyarray(py);
        let (bp, bs) = found.best;
        Ok((
            grid,
            score_rows(py, &scores)?,
            Array1::from(bp.to_vec()).into_pyarray(py),
            Array1::from(vec![bs.rms, bs.max, bs.line as f64]).into_pyarray(py),
            found.evaluations,
        ))
    }

    /// Samples of the run and of them cutting; stations of the search.
    #[getter]
    fn size(&self) -> (usize, usize, usize) {
        let (samples, cutting) = self.inner.loads().samples();
        (samples, cutting, self.inner.loads().stations().len())
    }

    /// Pickling: the job, the loads as bytes (not computed again), the seed.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, State<'py>)> {
        let py = slf.py();
        let rebuild = slf.get_type().getattr("_from_state")?;
        let me = slf.get();
        let bytes = PyBytes::new(py, &me.inner.loads().to_bytes());
        Ok((
            rebuild,
            (me.job.clone_ref(py), bytes, me.inner.seed().to_vec()),
        ))
    }

    /// The problem of a pickled state (see `__reduce__`).
    #[staticmethod]
    fn _from_state(job: Bound<'_, MachiningJob>, loads: &[u8], seed: Vec<f64>) -> PyResult<Self> {
        let (spin, optimise) = spin_of(job.get())?;
        let loads = LoadPath::from_bytes(loads).map_err(build_err)?;
        let core = job.get().job().clone();
        if seed.len() != core.model().dof() {
            return Err(InputError::new_err("pickled PlacementProblem: seed length"));
        }
        Ok(Self {
            inner: Problem::from_parts(core, loads, seed, spin, optimise),
            job: job.unbind(),
        })
    }
}

/// Registers the class.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PlacementProblem>()
}
