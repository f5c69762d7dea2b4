//! How a run is streamed: its chunks and threads ([`RunOptions`]), where its samples go
//! ([`Sink`]) and why it stopped ([`RunError`]).

use super::{DEFAULT_CHUNK, JobSample, MAX_CHUNK};
use crate::error::{BuildError, JobError};

/// How a run is cut into chunks and spread over threads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunOptions {
    /// Samples per chunk, 1..=[`MAX_CHUNK`]: the sink gets them together, and the memory of
    /// a streamed run grows with it (about 0.6 KB per sample).
    pub chunk: usize,
    /// Threads: 1 runs everything on the caller's; 2 or more (with the `std` feature) run the
    /// two predictions of each chunk side by side (the results do not depend on it).
    pub threads: usize,
}

impl Default for RunOptions {
    /// [`DEFAULT_CHUNK`] samples; two threads with `std`, one without.
    fn default() -> Self {
        Self {
            chunk: DEFAULT_CHUNK,
            threads: if cfg!(feature = "std") { 2 } else { 1 },
        }
    }
}

impl RunOptions {
    /// Checks the chunk size and the thread count.
    pub fn validate(&self) -> Result<(), BuildError> {
        crate::error::param(
            "chunk (samples)",
            self.chunk as f64,
            (1..=MAX_CHUNK).contains(&self.chunk),
            "1..=MAX_CHUNK (1048576) samples",
        )?;
        crate::error::param("threads", self.threads as f64, self.threads >= 1, ">= 1")?;
        Ok(())
    }
}

/// Where a streamed run's samples go, a chunk at a time, in time order.
pub trait Sink {
    /// What a failed write says.
    type Error;
    /// The next chunk of finished samples.
    fn samples(&mut self, chunk: &[JobSample]) -> Result<(), Self::Error>;
}

impl<E, F: FnMut(&[JobSample]) -> Result<(), E>> Sink for F {
    type Error = E;
    fn samples(&mut self, chunk: &[JobSample]) -> Result<(), E> {
        self(chunk)
    }
}

/// Why a streamed run stopped: the job failed, or the sink did.
#[derive(Debug, Clone, PartialEq)]
pub enum RunError<E> {
    /// The job (setup, a sample) failed.
    Job(JobError),
    /// The sink refused a chunk.
    Sink(E),
}

impl<E> From<JobError> for RunError<E> {
    fn from(e: JobError) -> Self {
        Self::Job(e)
    }
}

impl<E> From<BuildError> for RunError<E> {
    fn from(e: BuildError) -> Self {
        Self::Job(e.into())
    }
}

impl<E: core::fmt::Display> core::fmt::Display for RunError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Job(e) => write!(f, "{e}"),
            Self::Sink(e) => write!(f, "writing the samples: {e}"),
        }
    }
}
