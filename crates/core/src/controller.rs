//! A robot controller's conventions, and the configuration its Cartesian targets carry.
//!
//! A controller numbers, turns and zeroes its axes its own way: KUKA's A1, A4 and A6 turn
//! about the opposite axes of a URDF drawn with right-handed joints about +z and +x, ABB's
//! axis 2 reads zero with the lower arm upright. A [`Convention`] says, per joint, how the
//! controller's axis value follows from the model's (`controller = sign * model + offset`),
//! where the controller's base frame sits in the model's base frame, and where the TCP sits in
//! the controller's flange frame (KUKA's `$TOOL`, ABB's `tframe`, UR's `set_tcp`). It is data
//! of the robot's file (`[controller]` in its stiffness TOML, [`crate::io::stiffness`]).
//!
//! A Cartesian target alone is ambiguous on a six-axis arm (up to eight joint solutions and
//! their turns); each vendor adds words that pick one, computed here from the joints:
//!
//! - KUKA's status `S` and turn `T` ([`kuka_status_turn`]), as the KUKA System Software
//!   manuals define them: `S` bit 0 is set in the overhead area (the wrist point, the
//!   intersection of A4, A5 and A6, has a negative x in the A1 coordinate system: `$ROBROOT`
//!   turned with A1); bit 1 is set for `A3 >= phi`, the wrist point in front of the line
//!   through A2 and A3 (`phi` is the angle of A3 at which the wrist lies on that line: 0 when
//!   A3 and A4 intersect); bit 2 is set for `A5 <= 0`. `T` bit `i` is set where axis `i + 1`
//!   is below 0 degrees.
//! - ABB's `confdata` `[cf1, cf4, cf6, cfx]` ([`abb_confdata`]), as the RAPID reference
//!   defines it: `cf1`, `cf4`, `cf6` the quadrant of axes 1, 4 and 6 (`floor(angle / 90
//!   degrees)`: 0 for [0, 90), -1 for [-90, 0)), and `cfx` one of eight arm configurations:
//!   `4 x (wrist centre behind axis 1) + 2 x (behind the lower arm) + (axis 5 negative)`.
//!
//! "In front of the lower arm" is the side the arm reaches to when the lower arm is upright:
//! the wrist point turned positively about the controller's axis 2 (which tilts the lower
//! arm forward on KUKA's and ABB's arms) from the line through axes 2 and 3.

use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

use crate::error::{BuildError, TickError};
use crate::vjm::{self, Data, MAX_DOF, Model};

/// Which controller a [`Convention`] is for, and so which language and configuration words
/// its programs use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Vendor {
    /// KUKA KR C4 / KR C5 (KRL, `E6POS` with status and turn).
    Kuka,
    /// ABB IRC5 / OmniCore (RAPID, `robtarget` with `confdata`).
    Abb,
    /// Universal Robots CB3 / e-Series (URScript).
    UniversalRobots,
}

impl Vendor {
    /// Every vendor, in the order of their names.
    pub const ALL: [Self; 3] = [Self::Abb, Self::Kuka, Self::UniversalRobots];

    /// The name robot files use: `"kuka"`, `"abb"`, `"ur"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Kuka => "kuka",
            Self::Abb => "abb",
            Self::UniversalRobots => "ur",
        }
    }

    /// The vendor of a name ([`Self::name`]), `None` for another.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|v| v.name() == name)
    }

    /// The controller's language: `"KRL"`, `"RAPID"`, `"URScript"`.
    pub fn language(self) -> &'static str {
        match self {
            Self::Kuka => "KRL",
            Self::Abb => "RAPID",
            Self::UniversalRobots => "URScript",
        }
    }
}

/// Largest joint offset a convention takes \[rad or m\]: two turns.
pub const MAX_JOINT_OFFSET: f64 = 4.0 * core::f64::consts::PI;

/// How a controller reads the model's joints and frames (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convention {
    /// The controller.
    pub vendor: Vendor,
    /// Per joint in `q` order, +1 or -1: the controller's axis turns with (+1) or against
    /// (-1) the model's; entries past `dof` are 1.
    pub sign: [f64; MAX_DOF],
    /// Per joint: the controller's value where the model's is 0 \[rad or m\]; past `dof` 0.
    pub offset: [f64; MAX_DOF],
    /// Whether each joint is revolute (degrees in the programs) or prismatic (mm).
    pub revolute: [bool; MAX_DOF],
    /// Joints.
    pub dof: usize,
    /// The controller's base frame (KUKA `$ROBROOT`, ABB's base, UR's base) in the model's
    /// base frame.
    pub base: Isometry3<f64>,
    /// The TCP in the controller's flange frame (KUKA `$TOOL`, ABB `tooldata.tframe`, UR
    /// `set_tcp`).
    pub tool: Isometry3<f64>,
}

impl Convention {
    /// A convention for `model`: `sign` (each +1 or -1) and `offset` (finite, at most
    /// [`MAX_JOINT_OFFSET`]) one per joint, the frames finite. KUKA and ABB conventions need
    /// six joints (their configuration words describe a six-axis arm).
    pub fn new(
        vendor: Vendor,
        model: &Model,
        sign: &[f64],
        offset: &[f64],
        base: Isometry3<f64>,
        tool: Isometry3<f64>,
    ) -> Result<Self, BuildError> {
        let dof = model.dof();
        if matches!(vendor, Vendor::Kuka | Vendor::Abb) && dof != 6 {
            return Err(BuildError::DofMismatch {
                what: "controller convention (KUKA and ABB arms have six axes)",
                expected: 6,
                got: dof,
            });
        }
        for (what, v) in [
            ("controller joint sign", sign),
            ("controller joint offset", offset),
        ] {
            if v.len() != dof {
                return Err(BuildError::WrongLength {
                    what,
                    expected: dof,
                    got: v.len(),
                });
            }
        }
        let mut c = Self {
            vendor,
            sign: [1.0; MAX_DOF],
            offset: [0.0; MAX_DOF],
            revolute: [true; MAX_DOF],
            dof,
            base,
            tool,
        };
        for (index, (&s, &o)) in sign.iter().zip(offset).enumerate() {
            if s != 1.0 && s != -1.0 {
                return Err(BuildError::InvalidEntry {
                    what: "controller joint sign",
                    index,
                    value: s,
                    expected: "+1 or -1",
                });
            }
            if !(o.is_finite() && o.abs() <= MAX_JOINT_OFFSET) {
                return Err(BuildError::InvalidEntry {
                    what: "controller joint offset (rad or m)",
                    index,
                    value: o,
                    expected: "finite, at most MAX_JOINT_OFFSET (4 pi) in magnitude",
                });
            }
            if let (Some(cs), Some(co)) = (c.sign.get_mut(index), c.offset.get_mut(index)) {
                *cs = s;
                *co = o;
            }
        }
        for step in model.tcp_chain.iter() {
            if let Some(r) = c.revolute.get_mut(step.index) {
                *r = step.revolute;
            }
        }
        crate::error::check_frame("controller base frame", &base)?;
        crate::error::check_frame("controller tool frame", &tool)?;
        Ok(c)
    }

    /// The identity convention of `vendor` for `model` (the controller reads the model's
    /// joints and frames as they are, the TCP at the flange).
    pub fn identity(vendor: Vendor, model: &Model) -> Result<Self, BuildError> {
        let dof = model.dof();
        let ones = [1.0; MAX_DOF];
        let zeros = [0.0; MAX_DOF];
        Self::new(
            vendor,
            model,
            ones.get(..dof).unwrap_or(&[]),
            zeros.get(..dof).unwrap_or(&[]),
            Isometry3::identity(),
            Isometry3::identity(),
        )
    }

    /// The controller's axis values of the model's joints `q` (`sign * q + offset`, rad or
    /// m); entries past `dof` are 0.
    pub fn to_controller(&self, q: &[f64]) -> [f64; MAX_DOF] {
        let mut a = [0.0; MAX_DOF];
        for (i, (a, &q)) in a.iter_mut().zip(q).take(self.dof).enumerate() {
            *a = self.sign.get(i).copied().unwrap_or(1.0) * q
                + self.offset.get(i).copied().unwrap_or(0.0);
        }
        a
    }

    /// The model's joints of the controller's axis values `a` (the inverse of
    /// [`Self::to_controller`]).
    pub fn from_controller(&self, a: &[f64]) -> [f64; MAX_DOF] {
        let mut q = [0.0; MAX_DOF];
        for (i, (q, &a)) in q.iter_mut().zip(a).take(self.dof).enumerate() {
            *q = (a - self.offset.get(i).copied().unwrap_or(0.0))
                * self.sign.get(i).copied().unwrap_or(1.0);
        }
        q
    }

    /// A TCP pose in the model's base frame as the controller's base frame sees it.
    pub fn in_controller_base(&self, pose: &Isometry3<f64>) -> Isometry3<f64> {
        self.base.inverse() * pose
    }
}

/// Where a six-axis arm's wrist is at some joints, in the terms both vendors' configuration
/// words use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmConfiguration {
    /// The wrist point (the point of axis 5 nearest axis 4: their intersection on a
    /// spherical wrist) \[m\], model base frame.
    pub wrist: Vector3<f64>,
    /// The wrist point's x in the A1 coordinate system (the controller's base frame turned
    /// with axis 1) \[m\]: < 0 in KUKA's overhead area, behind axis 1 for ABB.
    pub x_in_axis1: f64,
    /// Which side of the line through axes 2 and 3 the wrist point lies on \[m^2\]: `((p3 -
    /// p2) x (w - p3)) . a2` with `a2` the controller's positive axis 2; > 0 in front of the
    /// lower arm (KUKA's `A3 >= phi`).
    pub front_of_lower_arm: f64,
    /// The controller's axis values \[rad or m\].
    pub axes: [f64; MAX_DOF],
}

/// The closest point on the line `(o_b, u_b)` to the line `(o_a, u_a)` (unit directions); the
/// point `o_b` where the lines are parallel.
fn nearest_on(
    o_a: &Vector3<f64>,
    u_a: &Vector3<f64>,
    o_b: &Vector3<f64>,
    u_b: &Vector3<f64>,
) -> Vector3<f64> {
    let w = o_b - o_a;
    let b = u_a.dot(u_b);
    let denominator = 1.0 - b * b;
    if denominator < 1.0e-12 {
        return *o_b;
    }
    let (d, e) = (u_a.dot(&w), u_b.dot(&w));
    let t = (b * d - e) / denominator;
    o_b + u_b * t
}

/// The wrist and arm geometry of a six-axis arm at the model's joints `q` (see
/// [`ArmConfiguration`]), for `convention`'s controller. Errors as [`vjm::joint_jacobian`];
/// [`TickError::WrongLength`] for a model that is not six-axis.
pub fn arm_configuration(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    convention: &Convention,
) -> Result<ArmConfiguration, TickError> {
    if model.dof() != 6 || convention.dof != 6 {
        return Err(TickError::WrongLength {
            what: "joints of a six-axis arm (configuration words)",
            expected: 6,
            got: model.dof(),
        });
    }
    vjm::joint_jacobian(model, data, q)?;
    let line = |i: usize| {
        data.joint_axis(i)
            .unwrap_or((Vector3::zeros(), Vector3::z()))
    };
    let ((o1, u1), (o2, u2), (o3, _), (o4, u4), (o5, u5)) =
        (line(0), line(1), line(2), line(3), line(4));
    let wrist = nearest_on(&o4, &u4, &o5, &u5);
    let axes = convention.to_controller(q);
    // The A1 coordinate system: the controller's base frame turned about axis 1 by the
    // controller's A1 (the model's angle from where the controller reads 0).
    let (s1, off1) = (convention.sign[0], convention.offset[0]);
    let turned = q.first().copied().unwrap_or(0.0) + off1 * s1;
    let back = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(u1), -turned);
    let w_back = o1 + back * (wrist - o1);
    let in_base = convention.base.inverse() * Point3::from(w_back);
    let a2 = u2 * convention.sign[1];
    let front = (o3 - o2).cross(&(wrist - o3)).dot(&a2);
    Ok(ArmConfiguration {
        wrist,
        x_in_axis1: in_base.x,
        front_of_lower_arm: front,
        axes,
    })
}

/// KUKA's status and turn of the model's joints `q` (see the module docs): `(S, T)`.
pub fn kuka_status_turn(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    convention: &Convention,
) -> Result<(u8, u8), TickError> {
    let c = arm_configuration(model, data, q, convention)?;
    let mut status = 0u8;
    if c.x_in_axis1 < 0.0 {
        status |= 1;
    }
    if c.front_of_lower_arm >= 0.0 {
        status |= 2;
    }
    if c.axes[4] <= 0.0 {
        status |= 4;
    }
    let mut turn = 0u8;
    for (i, a) in c.axes.iter().take(6).enumerate() {
        if *a < 0.0 {
            turn |= 1 << i;
        }
    }
    Ok((status, turn))
}

/// The quadrant ABB's `confdata` gives an axis angle \[rad\]: `floor(angle / 90 degrees)`.
pub fn abb_quadrant(angle: f64) -> i32 {
    let q = nalgebra::ComplexField::floor(angle / core::f64::consts::FRAC_PI_2);
    // Axis angles are at most a few turns: the quadrant fits.
    q.clamp(-1.0e6, 1.0e6) as i32
}

/// ABB's `confdata` `[cf1, cf4, cf6, cfx]` of the model's joints `q` (see the module docs).
pub fn abb_confdata(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    convention: &Convention,
) -> Result<[i32; 4], TickError> {
    let c = arm_configuration(model, data, q, convention)?;
    let mut cfx = 0;
    if c.x_in_axis1 < 0.0 {
        cfx += 4;
    }
    if c.front_of_lower_arm < 0.0 {
        cfx += 2;
    }
    if c.axes[4] < 0.0 {
        cfx += 1;
    }
    Ok([
        abb_quadrant(c.axes[0]),
        abb_quadrant(c.axes[3]),
        abb_quadrant(c.axes[5]),
        cfx,
    ])
}
