//! What the offline pass over a program predicts ([`super::job::run`]): every sample, the
//! part three ways, and the figures a machining engineer judges them by (path error, floors
//! and walls of the part, force per program line, the pilot-control signal).

use alloc::collections::BTreeMap;
use alloc::vec::Vec;

use nalgebra::{Isometry3, Vector3};

use super::engagement::Contact;
use super::path::PathSample;
use super::stock::ZMap;
use crate::vjm::{MAX_DOF, Vector6};

/// One sample of the offline pass. Positions and forces in the workpiece frame unless said.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JobSample {
    /// The programmed tool at this sample.
    pub path: PathSample,
    /// Where the nominal tool meets the nominal stock.
    pub contact: Contact,
    /// Feed per tooth \[m\] (horizontal speed / (spindle speed x flutes); 0 at rest).
    pub feed_per_tooth: f64,
    /// Per-revolution force on the tool from the nominal cut \[N\], workpiece frame.
    pub force: Vector3<f64>,
    /// The wrench on the TCP \[N, N m\], base frame, moment about the tip: what the
    /// compensation is computed for.
    pub wrench: Vector6,
    /// Rigid pose-IK joints of the programmed pose \[rad or m\]; entries past the dof are 0.
    pub q: [f64; MAX_DOF],
    /// Deflection `[dp; dr]` of the tip at `q` under `wrench` \[m, rad\], base frame: the
    /// process part.
    pub deflection: Vector6,
    /// The tool and spindle's D'Alembert wrench `[F; M]` \[N, N m\], base frame, about the tip,
    /// in the planned motion (zero without the job's [`super::job::Inertia`]).
    pub inertial_wrench: Vector6,
    /// Deflection `[dp; dr]` of the tip at `q` under the inertial loads alone (the wrench
    /// above and, when counted, the link masses') \[m, rad\], base frame: the inertial part
    /// (zero without the job's inertia). The predictions and the compensated joints carry
    /// both parts in one deflection.
    pub deflection_inertial: Vector6,
    /// The tool's planned acceleration \[m/s^2\], workpiece frame: along the feed and, on an
    /// arc, towards its centre ([`crate::machining::Move::curvature`]); in a corner blend the
    /// sum of both runs' ([`crate::machining::path::PathSample::acceleration_vector`]).
    pub tool_acceleration: Vector3<f64>,
    /// Compensated joints: the loaded tip reaches the programmed pose \[rad or m\].
    pub q_commanded: [f64; MAX_DOF],
    /// The Cartesian command: the rigid pose at `q_commanded`, workpiece frame.
    pub commanded: Isometry3<f64>,
    /// Predicted tip without compensation \[m\].
    pub actual_uncompensated: Vector3<f64>,
    /// Force the uncompensated tool feels where it is \[N\].
    pub force_uncompensated: Vector3<f64>,
    /// Predicted tip with compensation \[m\].
    pub actual_compensated: Vector3<f64>,
    /// Force the compensated tool feels where it is \[N\].
    pub force_compensated: Vector3<f64>,
    /// How far the last step of the force-deflection coupling moved each predicted tip
    /// (uncompensated, compensated) \[m\]: the residual of the fixed point (see
    /// [`super::job`]); at most [`super::job::COUPLING_TOLERANCE`] where it converged.
    pub coupling_residual: [f64; 2],
    /// The tool's spin about its own axis from the setup's orientation \[rad\] (the job's
    /// spin schedule; 0 without one).
    pub spin: f64,
}

/// Largest and root-mean-square values of a deviation \[m\].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorStats {
    /// Largest magnitude \[m\].
    pub max: f64,
    /// Root mean square \[m\].
    pub rms: f64,
    /// Entries counted.
    pub count: usize,
}

/// Largest and RMS of a stream of values, in constant memory.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorAccumulator {
    sum_squares: f64,
    count: usize,
    max: f64,
}

impl ErrorAccumulator {
    /// One more value.
    pub fn add(&mut self, v: f64) {
        self.sum_squares += v * v;
        self.count += 1;
        self.max = self.max.max(v.abs());
    }

    /// The values so far.
    pub fn stats(&self) -> ErrorStats {
        ErrorStats {
            max: self.max,
            rms: if self.count > 0 {
                nalgebra::ComplexField::sqrt(self.sum_squares / self.count as f64)
            } else {
                0.0
            },
            count: self.count,
        }
    }
}

/// A predicted part against the nominal one ([`Report::surface_error`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfaceError {
    /// Height above the nominal part over the cells both cut \[m\] (> 0: material left).
    pub floor: ErrorStats,
    /// Area the nominal part has cut and the predicted one not \[m^2\].
    pub material_left: f64,
    /// Area the predicted part has cut and the nominal one not \[m^2\].
    pub overcut: f64,
}

/// Why the compensated prediction leaves the program by more than
/// [`super::job::PREDICTION_TOLERANCE`] on a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Deviation {
    /// The force-deflection coupling did not converge within
    /// [`super::job::MAX_COUPLING_ITERATIONS`]: the force changes faster with the tool's
    /// position than the arm's stiffness holds the tool (beyond the model's offline
    /// compensation).
    Coupling,
    /// The compensated tool meets a stock the nominal tool did not: an earlier deviation
    /// left material the compensation, computed on the nominal stock, does not know of.
    Stock,
}

impl Deviation {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Coupling => "coupling",
            Self::Stock => "stock",
        }
    }
}

/// What one program line did: its force and how far the predictions left it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineSummary {
    /// Program line (1-based).
    pub line: usize,
    /// Samples on it.
    pub samples: usize,
    /// Mean force on the tool \[N\], workpiece frame.
    pub mean: Vector3<f64>,
    /// Largest force magnitude \[N\].
    pub max: f64,
    /// Largest distance of the uncompensated prediction from the program \[m\] (feed
    /// moves).
    pub error_uncompensated: f64,
    /// Largest distance of the compensated prediction from the program \[m\] (feed moves).
    pub error_compensated: f64,
    /// Largest coupling residual of the compensated prediction \[m\].
    pub residual: f64,
    /// Largest position part of the process deflection at the rigid joints \[m\].
    pub deflection_process: f64,
    /// Largest position part of the inertial deflection at the rigid joints \[m\] (0
    /// without the job's inertia).
    pub deflection_inertial: f64,
    /// Largest planned tool acceleration \[m/s^2\].
    pub peak_acceleration: f64,
    /// Why the compensated prediction leaves the program by more than
    /// [`super::job::PREDICTION_TOLERANCE`] here (`None` where it does not).
    pub deviation: Option<Deviation>,
}

/// The force per program line: [`LineSummary`] by its old name.
pub type LineForce = LineSummary;

impl LineSummary {
    fn new(line: usize) -> Self {
        Self {
            line,
            samples: 0,
            mean: Vector3::zeros(),
            max: 0.0,
            error_uncompensated: 0.0,
            error_compensated: 0.0,
            residual: 0.0,
            deflection_process: 0.0,
            deflection_inertial: 0.0,
            peak_acceleration: 0.0,
            deviation: None,
        }
    }

    fn add(&mut self, s: &JobSample) {
        self.samples += 1;
        // A running sum; `Summary::lines` divides.
        self.mean += s.force;
        self.max = self.max.max(s.force.norm());
        let [_, residual] = s.coupling_residual;
        self.residual = self.residual.max(residual);
        let position = |d: &Vector6| d.fixed_rows::<3>(0).norm();
        self.deflection_process = self.deflection_process.max(position(&s.deflection));
        self.deflection_inertial = self
            .deflection_inertial
            .max(position(&s.deflection_inertial));
        self.peak_acceleration = self.peak_acceleration.max(s.tool_acceleration.norm());
        if s.path.feed_move {
            let p = s.path.position;
            let (eu, ec) = (
                (s.actual_uncompensated - p).norm(),
                (s.actual_compensated - p).norm(),
            );
            self.error_uncompensated = self.error_uncompensated.max(eu);
            self.error_compensated = self.error_compensated.max(ec);
            if ec > super::job::PREDICTION_TOLERANCE {
                let why = if residual > super::job::COUPLING_TOLERANCE {
                    Deviation::Coupling
                } else {
                    Deviation::Stock
                };
                // Coupling failures name the line before stock differences do.
                if self.deviation != Some(Deviation::Coupling) {
                    self.deviation = Some(why);
                }
            }
        }
    }
}

/// The figures of a run, accumulated sample by sample in memory that grows with the
/// program's lines, not its samples: what a streamed run ([`super::job::run_streaming`])
/// reports.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    samples: usize,
    duration: f64,
    path: [ErrorAccumulator; 2],
    max_force: f64,
    residual: [f64; 2],
    deviating: usize,
    current: Option<LineSummary>,
    lines: BTreeMap<usize, LineSummary>,
}

impl Summary {
    /// One more sample (in time order).
    pub fn add(&mut self, s: &JobSample) {
        self.samples += 1;
        self.duration = s.path.time;
        self.max_force = self.max_force.max(s.force.norm());
        for (r, v) in self.residual.iter_mut().zip(s.coupling_residual) {
            *r = r.max(v);
        }
        if s.path.feed_move {
            let p = s.path.position;
            let ec = (s.actual_compensated - p).norm();
            let [u, c] = &mut self.path;
            u.add((s.actual_uncompensated - p).norm());
            c.add(ec);
            if ec > super::job::PREDICTION_TOLERANCE {
                self.deviating += 1;
            }
        }
        match &mut self.current {
            Some(l) if l.line == s.path.line => l.add(s),
            _ => {
                self.flush();
                let mut l = self
                    .lines
                    .remove(&s.path.line)
                    .unwrap_or_else(|| LineSummary::new(s.path.line));
                l.add(s);
                self.current = Some(l);
            }
        }
    }

    fn flush(&mut self) {
        if let Some(l) = self.current.take() {
            self.lines.insert(l.line, l);
        }
    }

    /// Samples counted.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Time of the last sample \[s\].
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// Distance of a predicted tip from the programmed one over the feed moves \[m\]
    /// (`compensated` false for the uncompensated arm).
    pub fn path_error(&self, compensated: bool) -> ErrorStats {
        let [u, c] = &self.path;
        if compensated { c.stats() } else { u.stats() }
    }

    /// The largest force on the tool \[N\].
    pub fn max_force(&self) -> f64 {
        self.max_force
    }

    /// The largest coupling residual of each prediction (uncompensated, compensated) \[m\].
    pub fn max_residual(&self) -> [f64; 2] {
        self.residual
    }

    /// Feed samples whose compensated prediction is further than
    /// [`super::job::PREDICTION_TOLERANCE`] from the program.
    pub fn deviating_samples(&self) -> usize {
        self.deviating
    }

    /// Every program line with samples, in line order, the mean force divided out.
    pub fn lines(&self) -> Vec<LineSummary> {
        let mut out: Vec<LineSummary> = self.lines.values().copied().collect();
        if let Some(c) = self.current {
            let at = out.partition_point(|l| l.line < c.line);
            out.insert(at, c);
        }
        for l in &mut out {
            l.mean /= l.samples.max(1) as f64;
        }
        out
    }
}

/// What the offline pass predicts.
#[derive(Debug, Clone)]
pub struct Report {
    /// Every sample, in time order ([`super::job::run`]; empty after a streamed run, whose
    /// samples went to its sink).
    pub samples: Vec<JobSample>,
    /// The figures over every sample.
    pub summary: Summary,
    /// The deepest a rapid move ran into the stock within [`super::job::Setup::rapid_skim`]
    /// (none if no rapid touched it).
    pub rapid_contact: Option<RapidContact>,
    /// The part as programmed.
    pub nominal: ZMap,
    /// The part the uncompensated arm cuts.
    pub uncompensated: ZMap,
    /// The part the compensated arm cuts.
    pub compensated: ZMap,
    /// Samples that plunge into material (feed along the tool axis): no side-milling force.
    pub plunge_samples: usize,
    /// Z-map cells lowered over the three stocks (the material removal's work).
    pub cell_updates: usize,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
    /// Joints of the arm.
    pub dof: usize,
    /// The stock's top \[m\].
    pub top: f64,
}

/// Where a rapid move ran into the predicted stock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RapidContact {
    /// Program line (1-based).
    pub line: usize,
    /// Time into the program \[s\].
    pub time: f64,
    /// The deepest cell it lowered \[m\].
    pub depth: f64,
}

impl Report {
    /// Distance of the predicted tip from the programmed one over the feed moves \[m\]:
    /// `compensated` false for the uncompensated arm.
    pub fn path_error(&self, compensated: bool) -> ErrorStats {
        self.summary.path_error(compensated)
    }

    /// A predicted part against the nominal one: the floors and the walls.
    ///
    /// A cell keeps the mean height over its area ([`super::stock`]), so a wall is a row of
    /// cells partly cut. Floors: the cells both parts cut (by more than
    /// [`super::engagement::MIN_DEPTH`]) whose four neighbours both parts cut too, height
    /// above the nominal (> 0 where material is left). Walls: every other cell either part
    /// cut counts the part of its area one part cut and the other did not, `(h_p - h_n) /
    /// (top - z)` of a cell for material left (and the opposite for overcut), `z` the lowest
    /// height around it (its floor) \[m^2\]: a wall moved sideways by `s` along a length `L`
    /// counts about `s L`, whether it crosses cells or stays within them.
    pub fn surface_error(&self, predicted: &ZMap) -> SurfaceError {
        let top = self.top;
        let cut = |h: f64| h < top - super::engagement::MIN_DEPTH;
        let area = self.nominal.cell() * self.nominal.cell();
        let (nx, ny) = self.nominal.shape();
        let (hn, hp) = (self.nominal.heights(), predicted.heights());
        let at = |h: &[f64], i: isize, j: isize| -> Option<f64> {
            if i < 0 || j < 0 || i as usize >= nx || j as usize >= ny {
                return None;
            }
            h.get(j as usize * nx + i as usize).copied()
        };
        let (mut left, mut over) = (0.0, 0.0);
        let mut floor = ErrorAccumulator::default();
        for j in 0..ny as isize {
            for i in 0..nx as isize {
                let (Some(n), Some(p)) = (at(hn, i, j), at(hp, i, j)) else {
                    continue;
                };
                if !cut(n) && !cut(p) {
                    continue;
                }
                let around = [(i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)];
                let interior = cut(n)
                    && cut(p)
                    && around.iter().all(|&(a, b)| {
                        at(hn, a, b).is_some_and(cut) && at(hp, a, b).is_some_and(cut)
                    });
                if interior {
                    floor.add(p - n);
                    continue;
                }
                let z = around
                    .iter()
                    .filter_map(|&(a, b)| Some(at(hn, a, b)?.min(at(hp, a, b)?)))
                    .fold(n.min(p), f64::min);
                let depth = top - z;
                if depth <= super::engagement::MIN_DEPTH {
                    continue;
                }
                let share = ((p - n) / depth).clamp(-1.0, 1.0);
                if share > 0.0 {
                    left += share * area;
                } else {
                    over -= share * area;
                }
            }
        }
        SurfaceError {
            floor: floor.stats(),
            material_left: left,
            overcut: over,
        }
    }

    /// The pilot-control signal of the annotated program (sec. 2.3 of Hähn and Weigold): the
    /// TCP wrench at each sample's time plus `lead` \[s\] (the paper's program carried its
    /// forces 40 ms early), the last wrench held at the end. `lead` is rounded to samples;
    /// negative or non-finite leads count as 0.
    pub fn pilot_wrenches(&self, lead: f64) -> Vec<Vector6> {
        let shift = if lead.is_finite() && lead > 0.0 {
            nalgebra::ComplexField::round(lead * self.rate_hz).min(usize::MAX as f64) as usize
        } else {
            0
        };
        let n = self.samples.len();
        (0..n)
            .filter_map(|k| {
                self.samples
                    .get(k.saturating_add(shift).min(n.saturating_sub(1)))
                    .map(|s| s.wrench)
            })
            .collect()
    }

    /// The force and the predictions' errors per program line, in line order.
    pub fn line_forces(&self) -> Vec<LineSummary> {
        self.summary.lines()
    }
}
