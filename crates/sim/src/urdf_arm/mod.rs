//! A flexible serial arm from any URDF and stiffness file, in rapier: the description
//! ([`spec`]: bodies, attachments, lumped link masses) and the simulated arm ([`sim`]: spring
//! joints for the virtual joints, servo motors with drive springs for the actuated joints;
//! its rapier multibody built by the private `build`).

mod build;
pub mod sim;
pub mod spec;

pub use sim::{FlexSerialArm, STIFF_RATIO, ServoParams};
pub use spec::{ArmSpec, Body, Inertia, Piece, RIGID, arm_spec};

/// The KR 300 R2500 URDF of deflect's `robots/` (the link masses are our estimates).
pub const KR300_URDF: &str = include_str!("../../../../robots/kr300/kr300_r2500.urdf");
/// Its stiffness file: Hähn and Weigold's identified values (2020, Table 1).
pub const KR300_STIFFNESS: &str =
    include_str!("../../../../robots/kr300/kr300_r2500_stiffness.toml");
/// The KR 300's milling pose \[rad\], tool pointing down (the examples' start pose).
pub const KR300_Q0: [f64; 6] = [0.0, -0.9, 1.4, 0.0, 1.0708, 0.0];

/// The built-in KR 300 R2500, base to `tcp`.
pub fn kr300() -> Result<ArmSpec, crate::SimError> {
    arm_spec(KR300_URDF, KR300_STIFFNESS, None, "tcp")
}
