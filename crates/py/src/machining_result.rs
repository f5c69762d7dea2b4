//! `deflect.MachiningResult`: what `MachiningJob.run` predicts, as arrays, part surfaces,
//! the compensated G-code and robot programs.

//! The offline pass over a program (deflect-core's `machining::job`): `MachiningJob` (the arm,
//! the workpiece placement, the tool, the material, the stock and how the program is driven)
//! and `MachiningResult` (every sample as arrays, the three predicted parts, the compensated
//! program). Thin: core runs the pass, with the GIL released.

use deflect_core::io::{job_out, robot_program};
use deflect_core::machining::Program;
use deflect_core::machining::job::{self, Report};
use deflect_core::machining::stock::ZMap;
use numpy::ndarray::{Array1, Array2, Ix3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use crate::InputError;
use crate::arrays::{put_pose, try_array, try_rows};

/// What `MachiningJob.run` predicts: every sample (arrays, SI, workpiece frame unless said),
/// the part three ways, and the compensated program.
#[pyclass(module = "deflect", frozen)]
#[derive(Debug)]
pub struct MachiningResult {
    pub(crate) report: Report,
    pub(crate) program: Program,
    /// The job it was run with (the arm, its placement and controller: the robot programs).
    pub(crate) job: job::Job,
    /// The robot's name in errors.
    pub(crate) robot_name: String,
    /// What the spin search found (`spin="optimize"`).
    pub(crate) spin_plan: Option<deflect_core::machining::spin::SpinPlan>,
}

impl MachiningResult {
    fn column<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&job::JobSample) -> f64,
    ) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.report.samples.iter().map(f)).into_pyarray(py)
    }

    fn rows<'py>(
        &self,
        py: Python<'py>,
        width: usize,
        fill: impl Fn(&job::JobSample, &mut [f64]),
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

    fn surface<'py>(&self, py: Python<'py>, z: &ZMap) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (nx, ny) = z.shape();
        let a = Array2::from_shape_vec((ny, nx), z.heights().to_vec())
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py))
    }

    fn which(&self, part: &str) -> PyResult<&ZMap> {
        match part {
            "uncompensated" => Ok(&self.report.uncompensated),
            "compensated" => Ok(&self.report.compensated),
            other => Err(InputError::new_err(format!(
                "part must be \"uncompensated\" or \"compensated\", got {other:?}"
            ))),
        }
    }
}

#[pymethods]
impl MachiningResult {
    fn __len__(&self) -> usize {
        self.report.samples.len()
    }

    /// Sample times (n,) [s].
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |s| s.path.time)
    }

    /// Program line of each sample (n,).
    #[getter]
    fn line<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.path.line as u64)).into_pyarray(py)
    }

    /// The tool in the spindle at each sample (n,) (its program's T; 0 for none).
    #[getter]
    fn tool<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        Array1::from_iter(self.report.samples.iter().map(|s| s.path.tool)).into_pyarray(py)
    }

    /// The program's spindle speed at each sample (n,) [rev/s]: > 0 clockwise (M3), < 0
    /// counter-clockwise (M4), 0 off (a hand-started spindle's speed is not in it).
    #[getter]
    fn spindle<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |s| s.path.spindle)
    }

    /// The deepest a rapid move ran into the predicted stock (within the job's
    /// `rapid_skim`): `(line, time [s], depth [m])`, or None.
    #[getter]
    fn rapid_contact(&self) -> Option<(usize, f64, f64)> {
        self.report.rapid_contact.map(|c| (c.line, c.time, c.depth))
    }

    /// Programmed tool tip (n, 3) [m].
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| o.copy_from_slice(s.path.position.as_slice()))
    }

    /// Unit feed direction of the programmed tool (n, 3).
    #[getter]
    fn direction<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| o.copy_from_slice(s.path.direction.as_slice()))
    }

    /// Engagement (n, 3): first entry, last exit [rad] and mean depth [m]; NaN where the
    /// tool is not side milling (air, plunge).
    #[getter]
    fn engagement<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| match s.contact.span() {
            Some(a) => o.copy_from_slice(&[a.entry, a.exit, a.depth]),
            None => o.fill(f64::NAN),
        })
    }

    /// Feed per tooth (n,) [m].
    #[getter]
    fn feed_per_tooth<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |s| s.feed_per_tooth)
    }

    /// Per-revolution force on the tool from the nominal cut (n, 3) [N].
    #[getter]
    fn force<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| o.copy_from_slice(s.force.as_slice()))
    }

    /// Force the uncompensated tool feels where it is (n, 3) [N].
    #[getter]
    fn force_uncompensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.force_uncompensated.as_slice())
        })
    }

    /// Force the compensated tool feels where it is (n, 3) [N].
    #[getter]
    fn force_compensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.force_compensated.as_slice())
        })
    }

    /// The last step of each prediction's force-deflection coupling (n, 2) [m]
    /// (uncompensated, compensated): at most 1e-8 m where the fixed point converged.
    #[getter]
    fn coupling_residual<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 2, |s, o| o.copy_from_slice(&s.coupling_residual))
    }

    /// Program lines where the compensated prediction leaves the program by more than 1 um:
    /// `(line, largest distance [m], reason)`, reason "coupling" (the force-deflection
    /// coupling did not converge) or "stock" (the compensated tool meets a stock an earlier
    /// deviation left). Empty where the compensation holds.
    #[getter]
    fn deviations(&self) -> Vec<(usize, f64, &'static str)> {
        self.report
            .line_forces()
            .iter()
            .filter_map(|l| l.deviation.map(|d| (l.line, l.error_compensated, d.name())))
            .collect()
    }

    /// The program's operations with their figures: per operation `(name, first_line,
    /// samples, max_force [N], path_error_uncompensated [m], path_error_compensated [m])`.
    #[getter]
    fn operations(&self) -> Vec<(String, usize, usize, f64, f64, f64)> {
        let n = self.program.operations.len().max(1);
        let mut out: Vec<(String, usize, usize, f64, f64, f64)> = (0..n)
            .map(|k| {
                let name = self
                    .program
                    .operations
                    .get(k)
                    .map_or_else(|| "program".to_string(), |o| o.name.clone());
                (name, 0, 0, 0.0, 0.0, 0.0)
            })
            .collect();
        for s in &self.report.samples {
            let k = self.program.operation_of(s.path.move_index);
            if let Some(o) = out.get_mut(k) {
                if o.2 == 0 {
                    o.1 = s.path.line;
                }
                o.2 += 1;
                o.3 = o.3.max(s.force.norm());
                if s.path.feed_move {
                    let p = s.path.position;
                    o.4 = o.4.max((s.actual_uncompensated - p).norm());
                    o.5 = o.5.max((s.actual_compensated - p).norm());
                }
            }
        }
        out.retain(|o| o.2 > 0);
        out
    }

    /// TCP wrench (n, 6) [N, N m], base frame, about the tool tip.
    #[getter]
    fn wrench<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 6, |s, o| o.copy_from_slice(s.wrench.as_slice()))
    }

    /// Deflection [dp; dr] of the tip (n, 6) [m, rad], base frame.
    #[getter]
    fn deflection<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 6, |s, o| o.copy_from_slice(s.deflection.as_slice()))
    }

    /// The inertial part of the deflection at `q` (n, 6) [m, rad], base frame: under the
    /// tool and spindle's D'Alembert wrench and the link loads alone (zero without
    /// `MachiningJob.with_inertia`).
    #[getter]
    fn deflection_inertial<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 6, |s, o| {
            o.copy_from_slice(s.deflection_inertial.as_slice())
        })
    }

    /// The tool and spindle's D'Alembert wrench (n, 6) [N, N m], base frame, about the tip.
    #[getter]
    fn inertial_wrench<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 6, |s, o| {
            o.copy_from_slice(s.inertial_wrench.as_slice())
        })
    }

    /// The tool's planned acceleration (n, 3) [m/s^2]: along the feed and towards an arc's
    /// centre.
    #[getter]
    fn tool_acceleration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.tool_acceleration.as_slice())
        })
    }

    /// Rigid pose-IK joints of the programmed path (n, dof).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.report.dof;
        self.rows(py, n, |s, o| o.copy_from_slice(s.q.get(..n).unwrap_or(&[])))
    }

    /// Compensated joints (n, dof): the axis-specific command.
    #[getter]
    fn q_commanded<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.report.dof;
        self.rows(py, n, |s, o| {
            o.copy_from_slice(s.q_commanded.get(..n).unwrap_or(&[]))
        })
    }

    /// Commanded poses (n, 4, 4), workpiece frame: the Cartesian command.
    #[getter]
    fn commanded<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let n = self.report.samples.len();
        let mut a = try_array(Ix3(n, 4, 4), "the samples")?;
        for (i, s) in self.report.samples.iter().enumerate() {
            put_pose(&mut a, i, &s.commanded);
        }
        Ok(a.into_pyarray(py))
    }

    /// Predicted tool tip without compensation (n, 3) [m].
    #[getter]
    fn actual_uncompensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.actual_uncompensated.as_slice())
        })
    }

    /// Predicted tool tip with compensation (n, 3) [m].
    #[getter]
    fn actual_compensated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, 3, |s, o| {
            o.copy_from_slice(s.actual_compensated.as_slice())
        })
    }

    /// The part as programmed: heights (ny, nx) [m], row j at y = origin_y + (j + 0.5) cell.
    #[getter]
    fn nominal_surface<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.surface(py, &self.report.nominal)
    }

    /// The part the uncompensated arm cuts, (ny, nx) [m].
    #[getter]
    fn uncompensated_surface<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.surface(py, &self.report.uncompensated)
    }

    /// The part the compensated arm cuts, (ny, nx) [m].
    #[getter]
    fn compensated_surface<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.surface(py, &self.report.compensated)
    }

    /// Lower corner (x, y) of the surfaces' cell (0, 0) [m] and the cell edge [m].
    #[getter]
    fn surface_grid(&self) -> ((f64, f64), f64) {
        let z = &self.report.nominal;
        ((z.origin().x, z.origin().y), z.cell())
    }

    /// Samples plunging into material (no side-milling force modelled there).
    #[getter]
    fn plunge_samples(&self) -> usize {
        self.report.plunge_samples
    }

    /// (max, rms) [m] of the predicted tip's distance from the program over the feed moves.
    #[pyo3(signature = (part="uncompensated"))]
    fn path_error(&self, part: &str) -> PyResult<(f64, f64)> {
        self.which(part)?;
        let e = self.report.path_error(part == "compensated");
        Ok((e.max, e.rms))
    }

    /// The predicted part against the nominal one: `floor_max`, `floor_rms` [m] over the
    /// cells both cut (height above nominal, > 0: material left) and the walls' shift as
    /// `material_left` and `overcut` [m^2] (areas cut by one part and not the other).
    #[pyo3(signature = (part="uncompensated"))]
    fn surface_error(&self, part: &str) -> PyResult<std::collections::HashMap<&'static str, f64>> {
        let e = self.report.surface_error(self.which(part)?);
        Ok([
            ("floor_max", e.floor.max),
            ("floor_rms", e.floor.rms),
            ("material_left", e.material_left),
            ("overcut", e.overcut),
        ]
        .into_iter()
        .collect())
    }

    /// The pilot-control signal (n, 6) [N, N m], base frame: each sample's TCP wrench `lead`
    /// [s] ahead (the annotated program of Hähn and Weigold, sec. 2.3; they used 40 ms).
    #[pyo3(signature = (lead=0.04))]
    fn pilot_wrenches<'py>(
        &self,
        py: Python<'py>,
        lead: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w = self.report.pilot_wrenches(checked_lead(lead)?);
        let mut out = try_rows(w.len(), 6, "the pilot wrenches")?;
        for (o, v) in out.chunks_mut(6).zip(&w) {
            o.copy_from_slice(v.as_slice());
        }
        let a = Array2::from_shape_vec((w.len(), 6), out)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        Ok(a.into_pyarray(py))
    }

    /// The compensated program as G-code text (mm), blocks kept within `tolerance` [m] of the
    /// commanded path.
    #[pyo3(signature = (tolerance=1e-6))]
    fn compensated_gcode(&self, tolerance: f64) -> PyResult<String> {
        let t = tolerance;
        if !(t.is_finite() && t > 0.0) {
            return Err(InputError::new_err(format!(
                "tolerance: expected > 0 m, got {t}"
            )));
        }
        Ok(job_out::compensated_gcode(&self.report, &self.program, t))
    }

    /// The compensated job as the robot controller's program (deflect-core's
    /// `io::robot_program`): `{file name: text}`, the main file first (KRL's `.src` then its
    /// `.dat`). `kind` "krl", "rapid", "urscript" or "csv"; `command` "cartesian" (the
    /// commanded TCP, kept within `tolerance` [m] and `tolerance / 0.1 m` rad) or "joints"
    /// (the compensated joints, within `joint_tolerance` [rad] for KRL and RAPID, every
    /// sample for URScript's `servoj` and the CSV). `acceleration` [m/s^2] is URScript's `a`,
    /// `tool_mass` [kg] RAPID's tool load, `name` the program's name. The robot's file must
    /// declare its controller (`[controller]`) for KRL, RAPID and URScript.
    #[pyo3(signature = (kind, *, command="cartesian", tolerance=1e-6, joint_tolerance=1e-6, acceleration=1.2, tool_mass=1.0, name="deflect_job"))]
    #[allow(clippy::too_many_arguments)]
    fn robot_program<'py>(
        &self,
        py: Python<'py>,
        kind: &str,
        command: &str,
        tolerance: f64,
        joint_tolerance: f64,
        acceleration: f64,
        tool_mass: f64,
        name: &str,
    ) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let err = |e: robot_program::ProgramError| match e {
            robot_program::ProgramError::Io { .. } => {
                pyo3::exceptions::PyOSError::new_err(e.to_string())
            }
            _ => InputError::new_err(e.to_string()),
        };
        let options = robot_program::ProgramOptions {
            name: name.to_string(),
            tolerance,
            joint_tolerance,
            acceleration,
            tool_mass,
            ..robot_program::ProgramOptions::new(
                robot_program::Language::from_name(kind).map_err(err)?,
                robot_program::Command::from_name(command).map_err(err)?,
            )
        };
        let setup = self.job.setup();
        let target = robot_program::Target {
            model: self.job.model(),
            convention: self.job.controller(),
            robot: &self.robot_name,
            placement: setup.placement,
            program: &self.program,
            rate_hz: self.report.rate_hz,
            rapid_speed: setup.path.rapid_speed,
        };
        let files = py
            .detach(|| robot_program::write(target, &self.report.samples, &options))
            .map_err(err)?;
        let out = pyo3::types::PyDict::new(py);
        for f in files {
            out.set_item(f.name, f.text)?;
        }
        Ok(out)
    }

    /// The tool's spin about its own axis at each sample (n,) [rad], from the setup's
    /// orientation (0 without `spin=`).
    #[getter]
    fn spin<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, |s| s.spin)
    }

    /// What the spin search found with `spin="optimize"` (else None): the predicted
    /// deflection [m] (RMS and largest of the measure over the cutting samples) of the
    /// optimised schedule (`optimised`), of the seed's constant spin (`seed`, None where it
    /// leaves the limits or its branch) and of the best constant spin (`best_constant`,
    /// with `best_constant_spin` [rad]); `stations`, `candidates`, `refused` nodes and the
    /// `measure`; `schedule`: the stations' spin budgets and spins (k, 2) [rad].
    #[getter]
    fn spin_plan<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, pyo3::types::PyDict>>> {
        let Some(p) = &self.spin_plan else {
            return Ok(None);
        };
        let d = pyo3::types::PyDict::new(py);
        let cost = |c: &deflect_core::machining::spin::SpinCost| (c.rms, c.max);
        d.set_item("optimised", cost(&p.optimised))?;
        d.set_item("seed", p.seed.as_ref().map(cost))?;
        d.set_item(
            "best_constant",
            p.best_constant.as_ref().map(|(_, c)| cost(c)),
        )?;
        d.set_item(
            "best_constant_spin",
            p.best_constant.as_ref().map(|(a, _)| *a),
        )?;
        d.set_item("stations", p.stations)?;
        d.set_item("candidates", p.candidates.len())?;
        d.set_item("refused", p.refused)?;
        d.set_item("measure", p.measure.name())?;
        let (b, s) = (p.schedule.budgets(), p.schedule.spins());
        let rows: Vec<f64> = b.iter().zip(s).flat_map(|(b, s)| [*b, *s]).collect();
        let a = Array2::from_shape_vec((b.len(), 2), rows)
            .map_err(|e| InputError::new_err(format!("internal: {e}")))?;
        d.set_item("schedule", a.into_pyarray(py))?;
        Ok(Some(d))
    }

    /// Every sample as CSV text (columns in deflect-core's `io::job_out::samples_csv`), the
    /// pilot wrench `lead` [s] ahead.
    #[pyo3(signature = (lead=0.04))]
    fn samples_csv(&self, lead: f64) -> PyResult<String> {
        Ok(job_out::samples_csv(&self.report, checked_lead(lead)?))
    }

    fn __repr__(&self) -> String {
        let (u, c) = (self.report.path_error(false), self.report.path_error(true));
        format!(
            "MachiningResult({} samples, path error max {:.3} mm uncompensated, {:.3} mm compensated)",
            self.report.samples.len(),
            u.max * 1e3,
            c.max * 1e3
        )
    }
}

/// A pilot lead \[s\]: finite and >= 0, else `InputError` naming it.
fn checked_lead(lead: f64) -> PyResult<f64> {
    if lead.is_finite() && lead >= 0.0 {
        Ok(lead)
    } else {
        Err(InputError::new_err(format!(
            "lead: expected >= 0 s, got {lead}"
        )))
    }
}
