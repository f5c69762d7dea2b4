//! The D'Alembert trajectory correction of Paksoy, Dede and Kiper (2025), "Enhancing
//! trajectory-tracking accuracy of high-acceleration parallel robots by predicting compliant
//! displacements", reproduced end to end: the paper's 2-DoF planar parallel robot (OC / NC,
//! upper / lower head; [`params`]) with compliant joints and finite-bandwidth servos
//! ([`robot`]),
//! simulated static tests, a fitted compliance map, the paper's motions at 1-5 g with and
//! without correction ([`run`]) and the paper's evaluation (Appendix C: [`analysis`] per path,
//! [`report`] as the paper's figures, [`output`] as tables, logs and plots).

pub mod analysis;
pub mod calibrate;
pub mod output;
pub mod params;
pub mod report;
pub mod robot;
pub mod run;
