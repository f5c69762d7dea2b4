//! A flexible serial arm from any URDF and stiffness file, in rapier: the description
//! ([`spec`]: bodies, attachments, lumped link masses) and the simulated arm ([`sim`]: spring
//! joints for the virtual joints, servo motors with drive springs for the actuated joints).

pub mod sim;
pub mod spec;

pub use sim::{FlexSerialArm, STIFF_RATIO, ServoParams};
pub use spec::{ArmSpec, Body, Inertia, Piece, RIGID, arm_spec};
