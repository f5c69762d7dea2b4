//! The quasi-static part of the force signal (VJM paper, section 2.2): a first-order low-pass
//! and a moving average, each with the delay it costs stated in samples and seconds.

use crate::error::{BuildError, param};
use crate::vjm::Vector6;

/// First-order IIR low-pass on a wrench, `y += alpha (x - y)`, `alpha = dt / (tau + dt)`,
/// `tau = 1 / (2 pi f_c)`. Its delay at low frequencies (group delay at DC) is
/// `(1 - alpha) / alpha` samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LowPass {
    alpha: f64,
    dt: f64,
    state: Vector6,
    primed: bool,
}

impl LowPass {
    /// Cut-off `cutoff_hz` \[Hz\] at sample time `dt` \[s\], both finite and > 0.
    pub fn new(cutoff_hz: f64, dt: f64) -> Result<Self, BuildError> {
        param("lowpass_cutoff_hz", cutoff_hz, cutoff_hz > 0.0, "> 0 (Hz)")?;
        param("dt", dt, dt > 0.0, "> 0 (s)")?;
        let tau = 1.0 / (2.0 * core::f64::consts::PI * cutoff_hz);
        Ok(Self {
            alpha: dt / (tau + dt),
            dt,
            state: Vector6::zeros(),
            primed: false,
        })
    }

    /// The smoothing factor `alpha` in (0, 1).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Low-frequency delay \[samples\].
    pub fn delay_samples(&self) -> f64 {
        (1.0 - self.alpha) / self.alpha
    }

    /// Low-frequency delay \[s\].
    pub fn delay_seconds(&self) -> f64 {
        self.delay_samples() * self.dt
    }

    /// Filters one sample. The first sample initialises the state (no start-up transient).
    pub fn step(&mut self, x: &Vector6) -> Vector6 {
        if self.primed {
            self.state += (x - self.state) * self.alpha;
        } else {
            self.state = *x;
            self.primed = true;
        }
        self.state
    }

    /// Forgets the history.
    pub fn reset(&mut self) {
        self.primed = false;
    }
}

/// Moving average of the last `window` wrenches (`window <= N`, N the buffer capacity fixed
/// at compile time so nothing allocates). Delay `(window - 1) / 2` samples once full; while
/// filling it averages what it has.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingAverage<const N: usize> {
    buffer: [Vector6; N],
    window: usize,
    len: usize,
    next: usize,
    dt: f64,
}

impl<const N: usize> MovingAverage<N> {
    /// A `window`-sample average at sample time `dt` \[s\]: `1 <= window <= N`, `dt` finite
    /// and > 0.
    pub fn new(window: usize, dt: f64) -> Result<Self, BuildError> {
        if window == 0 || window > N {
            return Err(BuildError::InvalidParameter {
                what: "moving_average_window",
                value: window as f64,
                expected: "in 1..=MAX_AVERAGE_WINDOW (64) samples",
            });
        }
        param("dt", dt, dt > 0.0, "> 0 (s)")?;
        Ok(Self {
            buffer: [Vector6::zeros(); N],
            window,
            len: 0,
            next: 0,
            dt,
        })
    }

    /// Window length \[samples\].
    pub fn window(&self) -> usize {
        self.window
    }

    /// Delay \[samples\] of a full window.
    pub fn delay_samples(&self) -> f64 {
        (self.window as f64 - 1.0) / 2.0
    }

    /// Delay \[s\] of a full window.
    pub fn delay_seconds(&self) -> f64 {
        self.delay_samples() * self.dt
    }

    /// Adds one sample and returns the average. The sum is recomputed from the buffer each
    /// time (at most `N` additions), so no rounding drift accumulates.
    pub fn step(&mut self, x: &Vector6) -> Vector6 {
        if let Some(slot) = self.buffer.get_mut(self.next) {
            *slot = *x;
        }
        self.next = (self.next + 1) % self.window;
        self.len = (self.len + 1).min(self.window);
        let sum: Vector6 = self.buffer.iter().take(self.len).sum();
        sum / self.len as f64
    }

    /// Forgets the history.
    pub fn reset(&mut self) {
        self.len = 0;
        self.next = 0;
    }
}
