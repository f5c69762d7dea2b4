//! Everything about a job but the arm and the program: the workpiece's placement, the tool
//! and material, the stock, how the program is driven and solved.

use nalgebra::{ComplexField, Isometry3, UnitQuaternion, Vector2, Vector3};

use crate::error::BuildError;
use crate::machining::cutting::{Coefficients, Tool};
use crate::machining::path::PathOptions;
use crate::machining::stock::ZMap;
use crate::machining::{Motion, Program};
use crate::mechanism::PoseIkOptions;

/// The stock: a block over `[min, max]` (x, y) with its top at `top`, workpiece frame \[m\],
/// resolved in square cells of `cell` \[m\] (see [`crate::machining::stock::MAX_CELLS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stock {
    /// Lower corner (x, y) \[m\].
    pub min: Vector2<f64>,
    /// Upper corner (x, y) \[m\].
    pub max: Vector2<f64>,
    /// Top face height \[m\].
    pub top: f64,
    /// Cell edge \[m\].
    pub cell: f64,
}

impl Stock {
    /// The (x, y) corners of a stock around `program`: the bounding box of its feed moves
    /// (arcs and helices sampled every 5 degrees) grown by `margin` \[m\] (a tool radius, so
    /// that the whole cut lies inside); `None` for a program without a feed move. What a user
    /// who gives no stock means: "a block that holds the part".
    pub fn around(program: &Program, margin: f64) -> Option<(Vector2<f64>, Vector2<f64>)> {
        let mut lo = Vector2::repeat(f64::INFINITY);
        let mut hi = Vector2::repeat(f64::NEG_INFINITY);
        for m in program.moves.iter().filter(|m| m.is_feed()) {
            for p in [m.start.xy(), m.end.xy()] {
                lo = lo.inf(&p);
                hi = hi.sup(&p);
            }
            if let Motion::Arc { sweep, .. } = m.motion {
                let n = (ComplexField::ceil(ComplexField::abs(sweep) / (5.0f64).to_radians())
                    as usize)
                    .clamp(2, 10_000);
                for k in 1..n {
                    let p = m.point(k as f64 / n as f64).xy();
                    lo = lo.inf(&p);
                    hi = hi.sup(&p);
                }
            }
        }
        (lo.x.is_finite() && hi.x.is_finite())
            .then(|| (lo - Vector2::repeat(margin), hi + Vector2::repeat(margin)))
    }
}

/// Everything about a job but the arm and the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// The workpiece frame in the robot's base frame.
    pub placement: Isometry3<f64>,
    /// The TCP frame's orientation in the workpiece frame; its z axis must lie along the
    /// workpiece's z (either way: the tool axis of a 2.5-D program).
    pub tool_orientation: UnitQuaternion<f64>,
    /// The end mill (a flat end mill of its diameter).
    pub tool: Tool,
    /// The material's cutting and edge coefficients.
    pub coefficients: Coefficients,
    /// The block the part is cut from.
    pub stock: Stock,
    /// How the program is driven and sampled.
    pub path: PathOptions,
    /// Pose IK settings (rigid and loaded); the full pose on an arm of fewer than six joints
    /// runs as the largest task it controls at the seed ([`super::Job::at_seed`]).
    pub ik: PoseIkOptions,
    /// Speed of a spindle the program does not start \[rev/s\] (a hand-started spindle: posts
    /// for such machines write no `M3`): it turns clockwise at this speed wherever the
    /// program's spindle is off. `None`: the program's spindle only.
    pub hand_spindle: Option<f64>,
    /// How deep a rapid move may run into the predicted stock \[m\] before the job refuses
    /// it ([`crate::error::JobError::RapidInStock`]); the deepest contact within it is reported
    /// ([`super::Report::rapid_contact`]). Default [`super::RAPID_SKIM`].
    pub rapid_skim: f64,
}

impl Setup {
    /// The TCP's z axis pointing down the workpiece z (out of the flange, into the part) and
    /// its x along the workpiece x: a rotation of pi about x.
    pub fn tool_down() -> UnitQuaternion<f64> {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), core::f64::consts::PI)
    }

    /// Checks the placement, stock (its cell budget, without allocating), tool,
    /// coefficients, path and IK options.
    pub fn validate(&self) -> Result<(), BuildError> {
        crate::error::check_frame(
            "placement (x, y, z, then quaternion i, j, k, w)",
            &self.placement,
        )?;
        let z = self.tool_orientation * Vector3::z();
        crate::error::param(
            "tool orientation (|z_tcp . z_workpiece|, must be 1)",
            z.z.abs(),
            (z.z.abs() - 1.0).abs() <= 1.0e-6,
            "the TCP z axis along the workpiece z (2.5-D program)",
        )?;
        let st = &self.stock;
        ZMap::shape_for(st.min, st.max, st.top, st.cell)?;
        self.tool.validate()?;
        self.coefficients.validate()?;
        self.path.validate()?;
        crate::error::param(
            "rapid skim (m)",
            self.rapid_skim,
            self.rapid_skim.is_finite() && (0.0..=0.1).contains(&self.rapid_skim),
            "in [0, 0.1] m",
        )?;
        if let Some(v) = self.hand_spindle {
            crate::error::param(
                "hand spindle speed (rev/s)",
                v,
                v > 0.0 && v <= crate::machining::MAX_SPINDLE_RPM / 60.0,
                "in (0, MAX_SPINDLE_RPM / 60] rev/s",
            )?;
        }
        self.ik.validate()
    }
}
