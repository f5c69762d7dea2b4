//! `MachiningJob.run_five_axis` and `deflect.FiveAxisResult` (deflect-core's
//! `machining::five_axis`): every sample as arrays, the tools' errors, the predicted parts'
//! machined surfaces with their deviation along the normal, and the PLY meshes. Thin: core
//! runs the pass and compares the parts, with the GIL released.

use std::path::PathBuf;

use deflect_core::io::ply;
use deflect_core::machining::dexel::Dexels;
use deflect_core::machining::dexel::surface::{Face, SurfaceMesh, SurfacePoint};
use deflect_core::machining::five_axis::{self, Options, Report, Sample};
use deflect_core::machining::job::Job;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;
use crate::arrays::try_rows;
use crate::errors::{job_err, tick_err};

/// What `MachiningJob.run_five_axis` predicts: every sample (arrays, SI, workpiece frame), the
/// tools the two arms hold, and the three parts cut (the program's and the two predictions).
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct FiveAxisResult {
    report: Report,
    /// The tools' length that removes material \[m\] (the default reach).
    length: f64,
}

/// Runs the pass (see `MachiningJob.run_five_axis`).
pub fn run(
    py: Python<'_>,
    job: &Job,
    program: &deflect_core::machining::Program,
    seed: &[f64],
    options: &Options,
) -> PyResult<FiveAxisResult> {
    let report = py
        .detach(|| five_axis::run(job, program, seed, options))
        .map_err(job_err)?;
    Ok(FiveAxisResult {
        report,
        length: options.length,
    })
}

impl FiveAxisResult {
    fn rows<'py>(
        &self,
        py: Python<'py>,
        width: usize,
        fill: impl Fn(&Sample, &mut [f64]),
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.report.samples.len();
        let mut out = try_rows(n, width, "the samples")?;
        for (s, o) in self.report.samples.iter().zip(out.chunks_mut(width)) {
            fill(s, o);
        }
        let a = Array2::from_shape_vec((n, width), out)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py))
    }

    fn part(&self, part: &str) -> PyResult<&Dexels> {
        match part {
            "uncompensated" => Ok(&self.report.uncompensated),
            "compensated" => Ok(&self.report.compensated),
            other => Err(InputError::new_err(format!(
                "part must be \"uncompensated\" or \"compensated\", got {other:?}"
            ))),
        }
    }

    /// The machined surface with `part`'s deviation, matched within `reach` (default: the
    /// farthest the uncompensated tool's edge left the program, its tip and its tilt along
    /// the flutes, plus two cells).
    fn points(&self, part: &str, reach: Option<f64>) -> PyResult<(Vec<SurfacePoint>, usize)> {
        let cell = self.report.nominal.cell();
        let e = self.report.errors(false);
        let reach = reach.unwrap_or(e.max_position + e.max_axis * self.length + 2.0 * cell);
        self.report
            .nominal
            .surface_deviation(self.part(part)?, reach)
            .map_err(tick_err)
    }
}

fn put(o: &mut [f64], v: &nalgebra::Vector3<f64>) {
    o.copy_from_slice(v.as_slice());
}

#[pymethods]
impl FiveAxisResult {
    fn __len__(&self) -> usize {
        self.report.samples.len()
    }

    /// Sample times (n,) [s].
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.path.time)).into_pyarray(py)
    }

    /// Program line of each sample (n,).
    #[getter]
    fn line<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.path.line as u64)).into_pyarray(py)
    }

    /// The spin about the tool axis per sample (n,) [rad] (the job's `spin`).
    #[getter]
    fn spin<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.spin)).into_pyarray(py)
    }

    /// Engaged bands along the edge per sample (n,): 0 where the tool cuts air.
    #[getter]
    fn bands<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.bands as u64)).into_pyarray(py)
    }

    /// Programmed tool tip (n, 3) [m].
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| put(o, &s.path.position))
    }

    /// Programmed tool axis (n, 3), unit, tip towards spindle.
    #[getter]
    fn axis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| put(o, &s.path.axis))
    }

    /// Force on the tool (n, 3) [N]: the cutter's per-revolution average along its edge on
    /// the engagement read from the nominal stock.
    #[getter]
    fn force<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| put(o, &s.force))
    }

    /// The wrench about the tip (n, 6) [N, N m].
    #[getter]
    fn wrench<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 6, |s, o| o.copy_from_slice(s.wrench.as_slice()))
    }

    /// Rigid pose-IK joints (n, dof) [rad or m].
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let dof = self.report.dof;
        self.rows(py, dof, |s, o| {
            o.copy_from_slice(s.q.get(..dof).unwrap_or(&[]))
        })
    }

    /// Compensated joints (n, dof) [rad or m].
    #[getter]
    fn q_commanded<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let dof = self.report.dof;
        self.rows(py, dof, |s, o| {
            o.copy_from_slice(s.q_commanded.get(..dof).unwrap_or(&[]));
        })
    }

    /// The tip the uncompensated arm holds under the wrench (n, 3) [m].
    #[getter]
    fn uncompensated_tip<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| put(o, &s.uncompensated.tip))
    }

    /// Its tool axis (n, 3), unit.
    #[getter]
    fn uncompensated_axis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| put(o, &s.uncompensated.axis))
    }

    /// The tip the compensated arm holds under the wrench (n, 3) [m].
    #[getter]
    fn compensated_tip<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| put(o, &s.compensated.tip))
    }

    /// Its tool axis (n, 3), unit.
    #[getter]
    fn compensated_axis<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| put(o, &s.compensated.axis))
    }

    /// The tool's errors over the cutting samples: a dict of `max_position` and
    /// `rms_position` [m], `max_axis` [rad] and `line` (of the largest tip error); `part` is
    /// "uncompensated" or "compensated".
    fn errors<'py>(&self, py: Python<'py>, part: &str) -> PyResult<Bound<'py, PyDict>> {
        let compensated = match part {
            "uncompensated" => false,
            "compensated" => true,
            other => {
                return Err(InputError::new_err(format!(
                    "part must be \"uncompensated\" or \"compensated\", got {other:?}"
                )));
            }
        };
        let e = self.report.errors(compensated);
        let d = PyDict::new(py);
        d.set_item("max_position", e.max_position)?;
        d.set_item("rms_position", e.rms_position)?;
        d.set_item("max_axis", e.max_axis)?;
        d.set_item("line", e.line)?;
        Ok(d)
    }

    /// The machined surface of the nominal part with `part`'s deviation along the outward
    /// normal: a dict of `position` (m, 3) [m], `normal` (m, 3), `deviation` (m,) [m] (> 0
    /// material left, < 0 overcut), `face` (m,) ("+x" .. "-z": the normal's side) and
    /// `unmatched` (points whose predicted surface lies beyond `reach` [m]; default the
    /// farthest the uncompensated tool's edge left the program plus two cells).
    #[pyo3(signature = (part="compensated", reach=None))]
    fn surface<'py>(
        &self,
        py: Python<'py>,
        part: &str,
        reach: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (points, missing) = py.detach(|| self.points(part, reach))?;
        let m = points.len();
        let (mut pos, mut nor) = (try_rows(m, 3, "surface")?, try_rows(m, 3, "surface")?);
        for ((p, a), b) in points.iter().zip(pos.chunks_mut(3)).zip(nor.chunks_mut(3)) {
            put(a, &p.position);
            put(b, &p.normal);
        }
        let shape = |v: Vec<f64>| {
            Array2::from_shape_vec((m, 3), v)
                .map_err(|e| InputError::new_err(format!("internal: {e}")))
        };
        let d = PyDict::new(py);
        d.set_item("position", shape(pos)?.into_pyarray(py))?;
        d.set_item("normal", shape(nor)?.into_pyarray(py))?;
        d.set_item(
            "deviation",
            Array1::from_iter(points.iter().map(|p| p.deviation)).into_pyarray(py),
        )?;
        let faces: Vec<&str> = points.iter().map(|p| Face::of(p).name()).collect();
        d.set_item("face", faces)?;
        d.set_item("unmatched", missing)?;
        Ok(d)
    }

    /// Writes `part`'s machined surface as a PLY mesh to `path` (binary, or `ascii=True`),
    /// the deviation as each vertex's `quality` [m]. `OSError` when the file cannot be
    /// written.
    #[pyo3(signature = (path, part="compensated", reach=None, ascii=false))]
    fn write_ply(
        &self,
        py: Python<'_>,
        path: PathBuf,
        part: &str,
        reach: Option<f64>,
        ascii: bool,
    ) -> PyResult<()> {
        let cell = self.report.nominal.cell();
        py.detach(|| -> PyResult<()> {
            let (points, _) = self.points(part, reach)?;
            let mesh = SurfaceMesh::new(points, cell).map_err(tick_err)?;
            let file = std::fs::File::create(&path).map_err(|e| {
                pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", path.display()))
            })?;
            let format = if ascii {
                ply::Format::Ascii
            } else {
                ply::Format::Binary
            };
            ply::write(&mesh, format, std::io::BufWriter::new(file)).map_err(|e| {
                pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", path.display()))
            })
        })
    }

    /// Rays the three stocks' cuts changed.
    #[getter]
    fn ray_updates(&self) -> usize {
        self.report.ray_updates
    }

    /// Material the program's rapids removed from the stock [m^3].
    #[getter]
    fn rapid_volume(&self) -> f64 {
        self.report.rapid_volume
    }

    fn __repr__(&self) -> String {
        let (u, c) = (self.report.errors(false), self.report.errors(true));
        format!(
            "FiveAxisResult({} samples, uncompensated tip max {:.4} mm, compensated {:.2e} mm)",
            self.report.samples.len(),
            u.max_position * 1e3,
            c.max_position * 1e3
        )
    }
}

/// Adds the class to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<FiveAxisResult>()
}
