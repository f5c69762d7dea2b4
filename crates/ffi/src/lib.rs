//! # deflect-ffi: the C API of deflect
//!
//! An `extern "C"` wrapper around deflect-core's real-time paths, so that C and C++ servo
//! controllers can link deflect as a static (`libdeflect.a`) or shared (`libdeflect.so`)
//! library. The header `include/deflect.h` is generated from these sources by cbindgen; a
//! test checks that the committed header is up to date.
//!
//! Layout: `boundary` (panic containment, pointer and string checks), [`status`] (the
//! codes and the one mapping from deflect-core's build, load and tick errors), then one
//! module per concept, each handle wrapping deflect-core's `Model` and `Data` (validation is
//! deflect-core's):
//!
//! | module | handle | what |
//! |---|---|---|
//! | [`robot`] | `DeflectSerialRobot` | a serial arm's VJM: deflection, compliance, joint correction |
//! | [`map`] | `DeflectComplianceMap` | the 2-D compliance map of static tests and its query |
//! | [`grid_map`] | `DeflectGridMap` | the N-D (1-4 axes) compliance map and its query |
//! | [`motion`] | `DeflectTrajectory2` | jerk-limited point-to-point and polyline motions |
//! | [`pose_motion`] | `DeflectPoseMotion` | motions in pose (position and orientation) |
//! | [`dalembert::parallel`] | `DeflectParallelRobot2`, `DeflectDalembert` | the five-bar and its D'Alembert corrector |
//! | [`dalembert::serial`] | `DeflectSerialDalembert` | a serial arm's 6-D D'Alembert corrector |
//! | [`dalembert::delta`] | `DeflectDelta`, `DeflectDeltaCorrector` | the Delta robot and its D'Alembert corrector |
//! | [`compensation`] | `DeflectCompensator` | online force-based compensation (filters, pilot control) |
//!
//! Conventions of the API:
//!
//! * Every name starts with `deflect_` / `Deflect` / `DEFLECT_`.
//! * Objects are opaque handles with an explicit `*_create`/`*_load`/`*_from_*` and
//!   `*_destroy`. Creating one allocates (init time); every per-tick function (`deflection`,
//!   `compliance`, `joint_correction`, `displacement`, `sample`, `step`) allocates nothing
//!   and runs in bounded time.
//! * Every fallible function returns a [`status::DeflectStatus`]: [`status::DEFLECT_OK`] (0) or a negative
//!   `DEFLECT_ERR_*` code. Outputs are written only on success (a failing `*_create` sets
//!   its handle output to NULL).
//! * Loaders take a caller-provided buffer `err`/`err_len` that receives the error message,
//!   NUL-terminated and truncated to fit (`err` may be NULL). [`status::deflect_status_message`]
//!   names any status code.
//! * No Rust panic crosses the boundary: every entry point runs under
//!   `std::panic::catch_unwind` and returns [`status::DEFLECT_ERR_PANIC`] instead.
//! * Units are SI: m, N, N m, rad, s, kg.
//! * Threads: a handle is not synchronised. A serial robot owns its workspace, so use it from
//!   one thread at a time; maps, trajectories and correctors are read-only after creation
//!   (except `deflect_compliance_map_set_options`) and may be read from several threads;
//!   a D'Alembert corrector keeps the last tick's joints and an online compensator its filter
//!   states: one thread at a time each.
// reason: a C API has to dereference the caller's raw pointers and hand out boxed handles;
// each unsafe block states its invariant in a SAFETY comment.
#![allow(unsafe_code)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

pub mod status;

pub mod compensation;
pub mod dalembert;
pub mod grid_map;
pub mod map;
pub mod motion;
pub mod pose_motion;
pub mod robot;

mod boundary;

pub use boundary::deflect_test_panic;
pub use compensation::*;
pub use dalembert::delta::*;
pub use dalembert::parallel::*;
pub use dalembert::serial::*;
pub use grid_map::*;
pub use map::*;
pub use motion::*;
pub use pose_motion::*;
pub use robot::*;
pub use status::*;
