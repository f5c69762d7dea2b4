//! What the offline pass over a program predicts ([`super::job::run`]): every sample, the
//! part three ways, and the figures a machining engineer judges them by (path error, floors
//! and walls of the part, force per program line, the pilot-control signal).

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
    /// Deflection `[dp; dr]` of the tip at `q` under `wrench` \[m, rad\], base frame.
    pub deflection: Vector6,
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

impl ErrorStats {
    fn of(values: impl Iterator<Item = f64>) -> Self {
        let (mut s, mut n, mut m) = (0.0, 0usize, 0.0f64);
        for v in values {
            s += v * v;
            n += 1;
            m = m.max(v.abs());
        }
        Self {
            max: m,
            rms: if n > 0 {
                nalgebra::ComplexField::sqrt(s / n as f64)
            } else {
                0.0
            },
            count: n,
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

/// Force statistics of one program line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineForce {
    /// Program line.
    pub line: usize,
    /// Samples on it.
    pub samples: usize,
    /// Mean force on the tool \[N\], workpiece frame.
    pub mean: Vector3<f64>,
    /// Largest force magnitude \[N\].
    pub max: f64,
}

/// What the offline pass predicts.
#[derive(Debug, Clone)]
pub struct Report {
    /// Every sample, in time order.
    pub samples: Vec<JobSample>,
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
        ErrorStats::of(self.samples.iter().filter(|s| s.path.feed_move).map(|s| {
            let a = if compensated {
                s.actual_compensated
            } else {
                s.actual_uncompensated
            };
            (a - s.path.position).norm()
        }))
    }

    /// A predicted part against the nominal one: the floors (cells both cut, by more than
    /// [`super::engagement::MIN_DEPTH`]: height above the nominal, > 0 where material is
    /// left), and the walls' shift as the areas cut by one and not the other \[m^2\] (a
    /// height map sees a wall moved sideways as a full-depth step; the areas measure it).
    pub fn surface_error(&self, predicted: &ZMap) -> SurfaceError {
        let cut = |h: f64| h < self.top - super::engagement::MIN_DEPTH;
        let area = self.nominal.cell() * self.nominal.cell();
        let (mut left, mut over) = (0usize, 0usize);
        let floor = ErrorStats::of(
            self.nominal
                .heights()
                .iter()
                .zip(predicted.heights())
                .filter_map(|(&n, &p)| match (cut(n), cut(p)) {
                    (true, true) => Some(p - n),
                    (true, false) => {
                        left += 1;
                        None
                    }
                    (false, true) => {
                        over += 1;
                        None
                    }
                    (false, false) => None,
                }),
        );
        SurfaceError {
            floor,
            material_left: left as f64 * area,
            overcut: over as f64 * area,
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

    /// The force per program line (lines with samples, in program order of first sample).
    pub fn line_forces(&self) -> Vec<LineForce> {
        let mut out: Vec<LineForce> = Vec::new();
        for s in &self.samples {
            match out.last_mut() {
                Some(l) if l.line == s.path.line => {
                    l.samples += 1;
                    l.mean += s.force;
                    l.max = l.max.max(s.force.norm());
                }
                _ => out.push(LineForce {
                    line: s.path.line,
                    samples: 1,
                    mean: s.force,
                    max: s.force.norm(),
                }),
            }
        }
        for l in &mut out {
            l.mean /= l.samples as f64;
        }
        out
    }
}
