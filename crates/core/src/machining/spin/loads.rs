//! What the spin (and placement) search needs of a program, computed once: the nominal
//! wrench at every cutting sample (the nominal tool on the nominal stock: it depends neither
//! on the arm's placement nor on the spin about the tool axis), and the stations where the
//! search decides the spin.
//!
//! Stations lie where the spin budget ([`super::schedule`]) has grown by a candidate step
//! since the last one and the path by at least [`MIN_STATION_PATH`], where a five-axis
//! program's tool axis has turned by a step (and at the first and last sample): between two stations the spin can turn by at least one step. Each cutting
//! sample is shared between the stations before and after it by its share of the budget
//! between them (hat weights: a linear interpolation's).

use alloc::vec::Vec;

use nalgebra::{Vector3, Vector6};

use super::schedule::budget_step;
use crate::error::{BuildError, JobError};
use crate::machining::Program;
use crate::machining::job::{self, Job};

/// Least path between two stations \[m\]: 0.5 mm (fast bounds do not make a station of every
/// sample).
pub const MIN_STATION_PATH: f64 = 5.0e-4;
/// Most stations: 2^17 (131 m of path at the closest spacing; the search keeps 6 bytes per
/// station and candidate).
pub const MAX_STATIONS: usize = 1 << 17;
/// Most cutting samples: 2^24 (18.6 h of cutting at 250 Hz; 40 bytes each).
pub const MAX_LOADED_SAMPLES: usize = 1 << 24;

/// A station: a sample where the spin is decided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Station {
    /// Its sample's index in the run.
    pub sample: usize,
    /// Its time \[s\].
    pub time: f64,
    /// Its program line.
    pub line: usize,
    /// The spin budget there \[rad\].
    pub budget: f64,
    /// The programmed tool tip \[m\], workpiece frame.
    pub position: Vector3<f64>,
    /// The programmed tool axis (unit, workpiece frame): `+z` in a 2.5-D program.
    pub axis: Vector3<f64>,
}

/// A cutting sample: its wrench and feed direction (single precision: what a ranking of
/// postures needs, at 40 bytes a sample) and its weight on the station after it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Load {
    /// Wrench about the tip \[N, N m\], workpiece frame.
    pub wrench: [f32; 6],
    /// Unit feed direction, workpiece frame.
    pub direction: [f32; 3],
    /// Its share on the next station (1 - on the one before).
    pub weight: f32,
}

impl Load {
    pub fn wrench(&self) -> Vector6<f64> {
        Vector6::from_iterator(self.wrench.iter().map(|&v| f64::from(v)))
    }

    pub fn direction(&self) -> Vector3<f64> {
        Vector3::from_iterator(self.direction.iter().map(|&v| f64::from(v)))
    }
}

/// The program's loads and stations for the spin rates and step it was built for.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadPath {
    pub(crate) stations: Vec<Station>,
    /// The cutting samples, in time order.
    pub(crate) loads: Vec<Load>,
    /// Per station `i`, the first load after station `i - 1` (loads up to and including the
    /// station's sample belong to its interval); one more entry closes the last.
    pub(crate) first_load: Vec<usize>,
    pub(crate) samples: usize,
    pub(crate) per_metre: f64,
    pub(crate) per_second: f64,
    pub(crate) step: f64,
}

impl LoadPath {
    /// Runs the nominal pass of `job` over `program` ([`job::nominal_pass`]) and places the
    /// stations for candidate spins `step` \[rad\] apart under the rate bounds `per_metre`
    /// \[rad/m\] and `per_second` \[rad/s\]. [`BuildError::Budget`] past [`MAX_STATIONS`] or
    /// [`MAX_LOADED_SAMPLES`]; the nominal pass's errors name their line.
    pub fn new(
        job: &Job,
        program: &Program,
        step: f64,
        per_metre: f64,
        per_second: f64,
    ) -> Result<Self, JobError> {
        Self::build(step, per_metre, per_second, |f| {
            job::nominal_pass(job, program, f)
        })
    }

    /// [`Self::new`] for a five-axis program: the nominal stage of
    /// [`crate::machining::five_axis`] (the cutters' forces along their edges on the
    /// engagement read from the tri-dexel stock, `options`), each station with the program's
    /// tool axis, about which the search turns the tool.
    pub fn new_five_axis(
        job: &Job,
        program: &Program,
        options: &crate::machining::five_axis::Options,
        step: f64,
        per_metre: f64,
        per_second: f64,
    ) -> Result<Self, JobError> {
        Self::build(step, per_metre, per_second, |f| {
            crate::machining::five_axis::nominal_pass(job, program, options, f)
        })
    }

    /// The load path of the samples `pass` hands its callback.
    fn build(
        step: f64,
        per_metre: f64,
        per_second: f64,
        pass: impl FnOnce(
            &mut dyn FnMut(&job::NominalSample) -> Result<(), JobError>,
        ) -> Result<(), JobError>,
    ) -> Result<Self, JobError> {
        super::schedule::check_rates(per_metre, per_second)?;
        super::check_step(step)?;
        let mut out = Self {
            stations: Vec::new(),
            loads: Vec::new(),
            first_load: Vec::new(),
            samples: 0,
            per_metre,
            per_second,
            step,
        };
        // Loads of the open interval with their budgets (weights set when it closes).
        let mut budgets: Vec<f64> = Vec::new();
        let (mut g, mut since_path) = (0.0f64, 0.0f64);
        let mut last_time: Option<f64> = None;
        let mut last: Option<Station> = None;
        let mut end: Option<Station> = None;
        pass(&mut |n: &job::NominalSample| {
            let dt = last_time
                .replace(n.path.time)
                .map_or(0.0, |t0| n.path.time - t0);
            g += budget_step(per_metre, per_second, &n.step, dt);
            since_path += n.step.norm();
            let index = out.samples;
            out.samples += 1;
            let station = Station {
                sample: index,
                time: n.path.time,
                line: n.path.line,
                budget: g,
                position: n.path.position,
                axis: n.path.axis,
            };
            if n.wrench.iter().any(|v| *v != 0.0) {
                if out.loads.len() >= MAX_LOADED_SAMPLES {
                    return Err(BuildError::Budget {
                        what: "spin search cutting samples",
                        budget: "MAX_LOADED_SAMPLES",
                        limit: MAX_LOADED_SAMPLES,
                        requested: out.loads.len() + 1,
                    }
                    .into());
                }
                let mut wrench = [0.0f32; 6];
                for (dst, v) in wrench.iter_mut().zip(n.wrench.iter()) {
                    *dst = *v as f32;
                }
                let d = n.path.direction;
                out.loads.push(Load {
                    wrench,
                    direction: [d.x, d.y, d.z].map(|v| v as f32),
                    weight: 1.0,
                });
                budgets.push(g);
            }
            // A station where the budget allows another step, or where the program's tool
            // axis has turned by a step since the last one (the joints follow the axis: the
            // next node must lie within the search's joint step of this one).
            let due = match last {
                None => true,
                Some(s) => {
                    (g - s.budget >= step && since_path >= MIN_STATION_PATH)
                        || crate::machining::program::angle_between(&s.axis, &n.path.axis) >= step
                }
            };
            if due {
                out.close(last.as_ref(), &station, &mut budgets)?;
                last = Some(station);
                since_path = 0.0;
            }
            end = Some(station);
            Ok(())
        })?;
        // The last sample is a station (unless it is one already).
        if let (Some(end), Some(l)) = (end, last)
            && end.sample != l.sample
        {
            out.close(Some(&l), &end, &mut budgets)?;
        }
        out.first_load.push(out.loads.len());
        Ok(out)
    }

    /// Closes the interval ending at `station`: its loads' weights, the station.
    fn close(
        &mut self,
        before: Option<&Station>,
        station: &Station,
        budgets: &mut Vec<f64>,
    ) -> Result<(), BuildError> {
        if self.stations.len() >= MAX_STATIONS {
            return Err(BuildError::Budget {
                what: "spin search stations (path and spin budget over the candidate step)",
                budget: "MAX_STATIONS",
                limit: MAX_STATIONS,
                requested: self.stations.len() + 1,
            });
        }
        let first = self.loads.len() - budgets.len();
        let g0 = before.map_or(station.budget, |b| b.budget);
        let span = station.budget - g0;
        for (load, g) in self
            .loads
            .get_mut(first..)
            .unwrap_or(&mut [])
            .iter_mut()
            .zip(budgets.iter())
        {
            load.weight = if span > 0.0 {
                ((g - g0) / span).clamp(0.0, 1.0) as f32
            } else {
                1.0
            };
        }
        budgets.clear();
        self.first_load.push(first);
        self.stations.push(*station);
        Ok(())
    }

    /// The stations.
    pub fn stations(&self) -> &[Station] {
        &self.stations
    }

    /// Samples of the run, and of them cutting (a wrench on the tool).
    pub fn samples(&self) -> (usize, usize) {
        (self.samples, self.loads.len())
    }

    /// The loads of station `i`'s two intervals: those before it (weight `w` on it) and
    /// those after it (weight `1 - w`).
    pub(crate) fn around(&self, i: usize) -> (&[Load], &[Load]) {
        let range = |k: usize| {
            let (a, b) = (
                self.first_load.get(k).copied().unwrap_or(self.loads.len()),
                self.first_load
                    .get(k + 1)
                    .copied()
                    .unwrap_or(self.loads.len()),
            );
            self.loads.get(a..b.max(a)).unwrap_or(&[])
        };
        (range(i), range(i + 1))
    }
}

/// The bytes format's first bytes (and version).
const MAGIC: &[u8; 8] = b"DFLLOAD2";

/// Reads little-endian numbers off a byte slice, refusing a short one.
struct Reader<'a> {
    bytes: &'a [u8],
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], BuildError> {
        let (head, rest) = self.bytes.split_at_checked(N).ok_or(BuildError::TooFew {
            what: "load path bytes",
            needed: N,
            got: self.bytes.len(),
        })?;
        self.bytes = rest;
        let mut out = [0u8; N];
        out.copy_from_slice(head);
        Ok(out)
    }
    /// `v`, refused where it is not finite.
    fn finite<T: Into<f64> + Copy>(v: T) -> Result<T, BuildError> {
        if v.into().is_finite() {
            Ok(v)
        } else {
            Err(BuildError::NonFinite {
                what: "load path bytes",
                index: 0,
            })
        }
    }
    fn f64(&mut self) -> Result<f64, BuildError> {
        Self::finite(f64::from_le_bytes(self.take()?))
    }
    fn f32(&mut self) -> Result<f32, BuildError> {
        Self::finite(f32::from_le_bytes(self.take()?))
    }
    fn count(&mut self, limit: usize, what: &'static str) -> Result<usize, BuildError> {
        let n = u64::from_le_bytes(self.take()?);
        let n = usize::try_from(n).unwrap_or(usize::MAX);
        if n > limit {
            return Err(BuildError::Budget {
                what,
                budget: "MAX_STATIONS / MAX_LOADED_SAMPLES",
                limit,
                requested: n,
            });
        }
        Ok(n)
    }
}

impl LoadPath {
    /// The load path as bytes (little-endian; what a worker of a placement search receives:
    /// the nominal pass is not run again there). [`Self::from_bytes`] reads them back, bit for
    /// bit.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(64 + self.stations.len() * 80 + self.loads.len() * 40);
        out.extend_from_slice(MAGIC);
        for v in [self.step, self.per_metre, self.per_second] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&(self.samples as u64).to_le_bytes());
        out.extend_from_slice(&(self.stations.len() as u64).to_le_bytes());
        for s in &self.stations {
            out.extend_from_slice(&(s.sample as u64).to_le_bytes());
            out.extend_from_slice(&s.time.to_le_bytes());
            out.extend_from_slice(&(s.line as u64).to_le_bytes());
            out.extend_from_slice(&s.budget.to_le_bytes());
            for v in s.position.iter().chain(s.axis.iter()) {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        out.extend_from_slice(&(self.loads.len() as u64).to_le_bytes());
        for l in &self.loads {
            for v in l
                .wrench
                .iter()
                .chain(&l.direction)
                .chain(core::iter::once(&l.weight))
            {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        for f in &self.first_load {
            out.extend_from_slice(&(*f as u64).to_le_bytes());
        }
        out
    }

    /// A load path of [`Self::to_bytes`]'s bytes, checked: sizes within the budgets, numbers
    /// finite, budgets not decreasing, intervals in order.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, BuildError> {
        let mut r = Reader { bytes };
        if r.take::<8>()? != *MAGIC {
            return Err(BuildError::InvalidParameter {
                what: "load path bytes (not deflect's format, or another version)",
                value: bytes.len() as f64,
                expected: "the bytes of LoadPath::to_bytes",
            });
        }
        let (step, per_metre, per_second) = (r.f64()?, r.f64()?, r.f64()?);
        super::schedule::check_rates(per_metre, per_second)?;
        super::check_step(step)?;
        let samples = r.count(usize::MAX >> 1, "load path samples")?;
        let n = r.count(MAX_STATIONS, "load path stations")?;
        let mut stations = Vec::new();
        for _ in 0..n {
            let sample = r.count(samples, "load path station sample")?;
            let time = r.f64()?;
            let line = r.count(usize::MAX >> 1, "load path station line")?;
            let budget = r.f64()?;
            let position = Vector3::new(r.f64()?, r.f64()?, r.f64()?);
            let axis = Vector3::new(r.f64()?, r.f64()?, r.f64()?);
            if (axis.norm() - 1.0).abs() > crate::machining::AXIS_TOLERANCE {
                return Err(BuildError::InvalidEntry {
                    what: "load path station tool axis (its length)",
                    index: stations.len(),
                    value: axis.norm(),
                    expected: "a unit vector (within AXIS_TOLERANCE)",
                });
            }
            if stations
                .last()
                .is_some_and(|s: &Station| budget < s.budget || sample < s.sample)
            {
                return Err(BuildError::NotIncreasing {
                    what: "load path stations (budget, sample)",
                    index: stations.len(),
                });
            }
            stations.push(Station {
                sample,
                time,
                line,
                budget,
                position,
                axis,
            });
        }
        let m = r.count(MAX_LOADED_SAMPLES, "load path cutting samples")?;
        let mut loads = Vec::new();
        for _ in 0..m {
            let mut v = [0.0f32; 10];
            for x in v.iter_mut() {
                *x = r.f32()?;
            }
            let [w0, w1, w2, w3, w4, w5, d0, d1, d2, weight] = v;
            loads.push(Load {
                wrench: [w0, w1, w2, w3, w4, w5],
                direction: [d0, d1, d2],
                weight,
            });
        }
        let mut first_load = Vec::new();
        for _ in 0..=n {
            let f = r.count(m, "load path interval start")?;
            if first_load.last().is_some_and(|p| f < *p) {
                return Err(BuildError::NotIncreasing {
                    what: "load path intervals",
                    index: first_load.len(),
                });
            }
            first_load.push(f);
        }
        if !r.bytes.is_empty() {
            return Err(BuildError::InvalidParameter {
                what: "load path bytes (trailing bytes)",
                value: r.bytes.len() as f64,
                expected: "none",
            });
        }
        Ok(Self {
            stations,
            loads,
            first_load,
            samples,
            per_metre,
            per_second,
            step,
        })
    }
}
