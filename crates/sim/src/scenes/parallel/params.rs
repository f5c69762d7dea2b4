//! The parallel robot's physical parameters (SI): the paper's dimensions and masses (section
//! 4.1), the two mechanism and head configurations, the stiffnesses, damping and servo gains
//! of one configuration ([`RobotParams`]), and the static compliance they give at the tool
//! point ([`linear_compliance`]).

use deflect_core::mechanism::ParallelRobot2;
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

use crate::SimError;

/// Simulation step \[s\]: the paper's 2 kHz servo rate.
pub const DT: f64 = crate::rapier_util::SERVO_DT;
/// Link length \[m\] (section 4.1).
pub const LINK: f64 = 0.150;
/// Half width |A0O| = |BC| \[m\].
pub const HALF_WIDTH: f64 = 0.090;
/// Moving platform with end effector \[kg\].
pub const PLATFORM_MASS: f64 = 3.6;
/// Thick distal link \[kg\].
pub const THICK_LINK_MASS: f64 = 0.2194;
/// Thin link \[kg\].
pub const THIN_LINK_MASS: f64 = 0.1236;
/// Intermediate platform \[kg\].
pub const INTERMEDIATE_MASS: f64 = 0.2512;
/// Actuated link: not reported by the paper ("assumed rigid"); our value \[kg\].
pub const ACTUATED_LINK_MASS: f64 = 0.30;
/// CoM height above G, upper head \[m\].
pub const D_UPPER: f64 = 0.0359;
/// CoM height above G, lower head \[m\].
pub const D_LOWER: f64 = 0.0053;
/// Tool point W (laser working point) below G \[m\]: our choice.
pub const Z_TOOL: f64 = 0.030;

/// Over- or normal-constrained mechanism.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum Constraint {
    /// Over-constrained (stiffer, symmetric).
    Oc,
    /// Normal-constrained (softer, arm B softer than arm A).
    Nc,
}

/// Head (laser) position: centre of mass high or low above G.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum Head {
    /// G_U: CoM 35.9 mm above G.
    Upper,
    /// G_L: CoM 5.3 mm above G.
    Lower,
}

impl Constraint {
    /// "OC" / "NC".
    pub fn label(self) -> &'static str {
        match self {
            Self::Oc => "OC",
            Self::Nc => "NC",
        }
    }
}

impl Head {
    /// "GU" / "GL".
    pub fn label(self) -> &'static str {
        match self {
            Self::Upper => "GU",
            Self::Lower => "GL",
        }
    }
    /// CoM height above G \[m\].
    pub fn com_height(self) -> f64 {
        match self {
            Self::Upper => D_UPPER,
            Self::Lower => D_LOWER,
        }
    }
}

/// Every physical parameter of one robot configuration (SI).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RobotParams {
    /// Mechanism variant.
    pub constraint: Constraint,
    /// Head position.
    pub head: Head,
    /// Drive stiffness of arm A \[N m/rad\].
    pub k_a: f64,
    /// Drive stiffness of arm B \[N m/rad\].
    pub k_b: f64,
    /// Relative damping of each drive spring \[N m s/rad\].
    pub c_drive: f64,
    /// Out-of-plane bending (tilt) stiffness of the head about G \[N m/rad\].
    pub k_tilt: f64,
    /// Tilt damping \[N m s/rad\].
    pub c_tilt: f64,
    /// Orientation stiffness of the parallelograms \[N m/rad\].
    pub k_orient: f64,
    /// Orientation damping \[N m s/rad\].
    pub c_orient: f64,
    /// Reflected motor inertia \[kg m^2\].
    pub j_motor: f64,
    /// Servo position gain \[N m/rad\].
    pub kp: f64,
    /// Servo velocity gain \[N m s/rad\].
    pub kd: f64,
    /// Head CoM height above G \[m\].
    pub com_height: f64,
    /// Tool point below G \[m\].
    pub z_tool: f64,
    /// rapier solver iterations (substeps).
    pub solver_iterations: usize,
    /// rapier internal PGS iterations per substep.
    pub pgs_iterations: usize,
}

impl RobotParams {
    /// The documented defaults of one configuration.
    ///
    /// Stiffnesses were chosen so that the static compliance over the paper's grid is of the
    /// order of its tables: OC about 0.2-0.5 mm, NC about 0.4-1.1 mm of displacement at
    /// 245 N. Damping ratios are a few percent; the servo loop has about 250 Hz bandwidth.
    pub fn new(constraint: Constraint, head: Head) -> Self {
        let (k_a, k_b, k_tilt) = match constraint {
            Constraint::Oc => (16_000.0, 16_000.0, 2_500.0),
            Constraint::Nc => (9_000.0, 7_000.0, 1_500.0),
        };
        let j_motor = 0.05;
        let w = 2.0 * core::f64::consts::PI * 250.0;
        Self {
            constraint,
            head,
            k_a,
            k_b,
            c_drive: 3.0,
            k_tilt,
            c_tilt: 0.5,
            k_orient: 40_000.0,
            c_orient: 2.0,
            j_motor,
            kp: j_motor * w * w,
            kd: 2.0 * 0.7 * w * j_motor,
            com_height: head.com_height(),
            z_tool: Z_TOOL,
            solver_iterations: 1,
            pgs_iterations: 4,
        }
    }

    /// "OC GU" etc.
    pub fn label(&self) -> String {
        format!("{} {}", self.constraint.label(), self.head.label())
    }
}

/// The linearized static compliance of the model at the tool point for an in-plane force at
/// G: `J K^-1 J^T` \[m/N\] over the three elastic coordinates of the closed chain,
/// `K = diag(k_a, k_b, k_orient)` (the two drive springs and the parallelograms' orientation
/// spring) and `J = d(x, y, psi)/d(theta_a, theta_b, psi)` at the tool point `p` \[m\] (x, y
/// block returned). Without the orientation spring (`k_orient -> inf`) this is the robot's
/// 2 x 2 `J K^-1 J^T` with [`ParallelRobot2::jacobian_at`].
///
/// `J^-1` is built by central differences of the arms' closed-form IK: with the platform
/// rotated by `psi`, arm A reaches `D - A0 = p + R(psi) (0, h) - (0, h)` and arm B
/// `E - B0 = p + R(psi) (0, -h) - (0, -h)`.
pub fn linear_compliance(params: &RobotParams, p: &Vector2<f64>) -> Result<Matrix2<f64>, SimError> {
    let mech = ParallelRobot2::paper();
    let h = HALF_WIDTH;
    let joints = |x: f64, y: f64, psi: f64| -> Result<Vector3<f64>, SimError> {
        let (s, c) = psi.sin_cos();
        let ta = Vector2::new(x - h * s, y + h * c - h);
        let tb = Vector2::new(x + h * s, y - h * c + h);
        Ok(Vector3::new(mech.ik(&ta)?.x, mech.ik(&tb)?.y, psi))
    };
    let e = 1e-7;
    let mut jinv = Matrix3::zeros();
    for k in 0..3 {
        let mut dp = Vector3::zeros();
        dp[k] = e;
        let plus = joints(p.x + dp.x, p.y + dp.y, dp.z)?;
        let minus = joints(p.x - dp.x, p.y - dp.y, -dp.z)?;
        jinv.set_column(k, &((plus - minus) / (2.0 * e)));
    }
    let j = jinv
        .try_inverse()
        .ok_or_else(|| SimError::new("singular pose in linear_compliance"))?;
    let kinv = Matrix3::from_diagonal(&Vector3::new(
        1.0 / params.k_a,
        1.0 / params.k_b,
        1.0 / params.k_orient,
    ));
    let c = j * kinv * j.transpose();
    Ok(Matrix2::new(c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)]))
}
