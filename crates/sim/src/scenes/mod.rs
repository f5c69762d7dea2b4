//! The testbed's scenes, one folder per domain, each with its robot or arm, its run and its
//! outputs:
//!
//! | scene | paper | robot in rapier | command |
//! |---|---|---|---|
//! | [`parallel`] | Paksoy, Dede and Kiper 2025: D'Alembert correction with a compliance map | the 2-DoF five-bar, compliant joints, servos | `reproduce`, `static-test`, `fit`, `run` |
//! | [`milling`] | Hähn and Weigold 2020: online force-based compensation | the flexible KR 300 R2500 ([`crate::urdf_arm`]) | `milling` |
//! | [`contour`] | "Shape recovery from robot contour tracking with force feedback" | a 2R arm with compliant, backlashed joints | `contour` |
//! | [`delta`] | Paksoy et al.'s correction on the Delta robot with a 3-D compliance map | a Delta with compliant drives, forearm rods on ball joints, servos | `delta` |
//! | [`serial`] | Paksoy et al.'s correction in 6-D on any serial arm; the stiffness-optimal posture | any URDF arm ([`crate::urdf_arm`]) | `serial`, `atlas` |

pub mod contour;
pub mod delta;
pub mod milling;
pub mod parallel;
pub mod serial;
