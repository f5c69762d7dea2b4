//! A trajectory given as the user's own positions at a fixed rate (`alloc`): velocities and
//! accelerations by second-order finite differences, or accelerations given.
//!
//! With `h = 1 / rate_hz` and samples `p_0 .. p_(n-1)`:
//!
//! * velocity: central `(p_(k+1) - p_(k-1)) / 2h` inside; one-sided second order at the ends,
//!   `(-3 p_0 + 4 p_1 - p_2) / 2h` and `(3 p_(n-1) - 4 p_(n-2) + p_(n-3)) / 2h`;
//! * acceleration: central `(p_(k+1) - 2 p_k + p_(k-1)) / h^2` inside; one-sided second
//!   order at the ends, `(2 p_0 - 5 p_1 + 4 p_2 - p_3) / h^2` and its mirror;
//! * jerk: central differences of the accelerations, one-sided first order at the ends.
//!
//! All are exact for polynomials of degree 2 (degree 3 for the central velocity). Sampling
//! noise is amplified by `1 / h^2` in the accelerations: filter measured paths first, or give
//! the accelerations.

use alloc::vec::Vec;

use nalgebra::SVector;

use super::{MAX_SAMPLES, PathState, State};
use crate::error::{BuildError, TickError};

/// The user's sampled trajectory with its derivatives (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SampledTrajectory<const N: usize> {
    rate_hz: f64,
    position: Vec<SVector<f64, N>>,
    velocity: Vec<SVector<f64, N>>,
    acceleration: Vec<SVector<f64, N>>,
    jerk: Vec<SVector<f64, N>>,
}

fn check_rate(rate_hz: f64) -> Result<f64, BuildError> {
    // A sub-normal rate makes the step infinite (every difference NaN).
    crate::error::param(
        "rate_hz",
        rate_hz,
        rate_hz.is_normal() && rate_hz > 0.0,
        "finite and > 0 (Hz, not sub-normal)",
    )
}

/// Refuses differences that overflowed (samples near `f64::MAX`, or a rate so high that
/// `1 / rate^2` underflows the step) and a duration that did: the caller would get
/// infinities or NaN for a motion no controller can run.
fn check_differences<const N: usize>(t: &SampledTrajectory<N>) -> Result<(), BuildError> {
    for (what, v) in [
        (
            "samples and rate_hz (the velocities' finite differences overflow)",
            &t.velocity,
        ),
        (
            "samples and rate_hz (the accelerations' finite differences overflow)",
            &t.acceleration,
        ),
        (
            "samples and rate_hz (the jerks' finite differences overflow)",
            &t.jerk,
        ),
    ] {
        if let Some(bad) = v.iter().flat_map(|p| p.iter()).find(|c| !c.is_finite()) {
            return Err(BuildError::InvalidParameter {
                what,
                value: *bad,
                expected: "samples and a rate whose finite differences are finite",
            });
        }
    }
    let duration = t.duration();
    if !duration.is_finite() {
        return Err(BuildError::InvalidParameter {
            what: "rate_hz (the duration of the samples overflows)",
            value: t.rate_hz,
            expected: "a rate that gives a finite duration",
        });
    }
    Ok(())
}

fn check_samples<const N: usize>(
    what: &'static str,
    v: &[SVector<f64, N>],
) -> Result<(), BuildError> {
    if v.len() > MAX_SAMPLES {
        return Err(BuildError::Budget {
            what: "samples",
            budget: "MAX_SAMPLES",
            limit: MAX_SAMPLES,
            requested: v.len(),
        });
    }
    match v.iter().flat_map(|p| p.iter()).position(|c| !c.is_finite()) {
        Some(index) => Err(BuildError::NonFinite { what, index }),
        None => Ok(()),
    }
}

/// First derivative of `p` at step `h` by the stencils of the module docs (`p.len() >= 3`).
fn derivative<const N: usize>(p: &[SVector<f64, N>], h: f64) -> Vec<SVector<f64, N>> {
    let n = p.len();
    (0..n)
        .map(|k| {
            let at = |i: usize| p.get(i).copied().unwrap_or_else(SVector::zeros);
            if k == 0 {
                (at(0) * -3.0 + at(1) * 4.0 - at(2)) / (2.0 * h)
            } else if k + 1 == n {
                (at(k) * 3.0 - at(k - 1) * 4.0 + at(k - 2)) / (2.0 * h)
            } else {
                (at(k + 1) - at(k - 1)) / (2.0 * h)
            }
        })
        .collect()
}

/// Central differences inside, one-sided first order at the ends.
fn simple_derivative<const N: usize>(p: &[SVector<f64, N>], h: f64) -> Vec<SVector<f64, N>> {
    let n = p.len();
    (0..n)
        .map(|k| {
            let at = |i: usize| p.get(i).copied().unwrap_or_else(SVector::zeros);
            if k == 0 {
                (at(1) - at(0)) / h
            } else if k + 1 == n {
                (at(k) - at(k - 1)) / h
            } else {
                (at(k + 1) - at(k - 1)) / (2.0 * h)
            }
        })
        .collect()
}

impl<const N: usize> SampledTrajectory<N> {
    /// From positions at `rate_hz` (at least 4 samples, at most [`MAX_SAMPLES`]).
    /// [`BuildError::InvalidParameter`] when a finite difference or the duration overflows.
    pub fn from_positions(
        rate_hz: f64,
        position: Vec<SVector<f64, N>>,
    ) -> Result<Self, BuildError> {
        let rate_hz = check_rate(rate_hz)?;
        check_samples("positions (flattened)", &position)?;
        let n = position.len();
        if n < 4 {
            return Err(BuildError::TooFew {
                what: "samples (4 for second-order end accelerations)",
                needed: 4,
                got: n,
            });
        }
        let h = 1.0 / rate_hz;
        let at = |i: usize| position.get(i).copied().unwrap_or_else(SVector::zeros);
        let acceleration: Vec<_> = (0..n)
            .map(|k| {
                if k == 0 {
                    (at(0) * 2.0 - at(1) * 5.0 + at(2) * 4.0 - at(3)) / (h * h)
                } else if k + 1 == n {
                    (at(k) * 2.0 - at(k - 1) * 5.0 + at(k - 2) * 4.0 - at(k - 3)) / (h * h)
                } else {
                    (at(k + 1) - at(k) * 2.0 + at(k - 1)) / (h * h)
                }
            })
            .collect();
        let velocity = derivative(&position, h);
        let jerk = simple_derivative(&acceleration, h);
        let t = Self {
            rate_hz,
            position,
            velocity,
            acceleration,
            jerk,
        };
        check_differences(&t)?;
        Ok(t)
    }

    /// From positions and their accelerations (the same number of samples, at least 3).
    pub fn from_positions_and_accelerations(
        rate_hz: f64,
        position: Vec<SVector<f64, N>>,
        acceleration: Vec<SVector<f64, N>>,
    ) -> Result<Self, BuildError> {
        let rate_hz = check_rate(rate_hz)?;
        check_samples("positions (flattened)", &position)?;
        check_samples("accelerations (flattened)", &acceleration)?;
        if acceleration.len() != position.len() {
            return Err(BuildError::WrongLength {
                what: "accelerations (one per position)",
                expected: position.len(),
                got: acceleration.len(),
            });
        }
        if position.len() < 3 {
            return Err(BuildError::TooFew {
                what: "samples",
                needed: 3,
                got: position.len(),
            });
        }
        let h = 1.0 / rate_hz;
        let velocity = derivative(&position, h);
        let jerk = simple_derivative(&acceleration, h);
        let t = Self {
            rate_hz,
            position,
            velocity,
            acceleration,
            jerk,
        };
        check_differences(&t)?;
        Ok(t)
    }

    /// Sampling rate \[Hz\].
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.position.len()
    }
    /// Whether there are no samples (never, once built).
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
    /// Duration `(n - 1) / rate_hz` \[s\].
    pub fn duration(&self) -> f64 {
        self.len().saturating_sub(1) as f64 / self.rate_hz
    }

    /// The state of sample `k` (`path` is zero: a sampled path has no profile).
    pub fn state(&self, k: usize) -> Result<State<N>, TickError> {
        let get = |v: &Vec<SVector<f64, N>>| v.get(k).copied();
        match (
            get(&self.position),
            get(&self.velocity),
            get(&self.acceleration),
            get(&self.jerk),
        ) {
            (Some(position), Some(velocity), Some(acceleration), Some(jerk)) => Ok(State {
                t: k as f64 / self.rate_hz,
                segment: 0,
                path: PathState::default(),
                position,
                velocity,
                acceleration,
                jerk,
            }),
            _ => Err(TickError::InvalidArgument {
                what: "sample index",
                value: k as f64,
            }),
        }
    }
}
