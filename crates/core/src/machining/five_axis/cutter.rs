//! One cutter as the five-axis pass models it (its edge for the force, its solid for the
//! stock) and the wrench of an engagement on it: shared by the pass and by a simulation
//! that reads the engagement where its own tool is.

use nalgebra::{Rotation3, Vector3};

use crate::error::{BuildError, TickError};
use crate::machining::cutting::{Coefficients, Tool, tool_frame};
use crate::machining::dexel::DexelTool;
use crate::machining::profile::{self, Band, Cut, Profile, ToolShape};
use crate::vjm::Vector6;

/// A cutter: the tool (diameter, flutes, helix), its profile along the edge and its solid
/// up to the length that removes material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutterModel {
    /// Diameter, flutes, helix.
    pub tool: Tool,
    /// The edge's profile (flat, ball or bull-nose end).
    pub profile: Profile,
    /// The solid the stock is cut with.
    pub solid: DexelTool,
}

impl CutterModel {
    /// The cutter of `tool` with end `shape`, removing material up to `length` \[m\] above
    /// its tip. Errors of [`Profile::new`] and [`DexelTool::new`].
    pub fn new(tool: &Tool, shape: ToolShape, length: f64) -> Result<Self, BuildError> {
        let profile = Profile::new(tool, shape)?;
        Ok(Self {
            tool: *tool,
            profile,
            solid: DexelTool::new(&profile, length)?,
        })
    }
}

/// The tool frame for tool axis `axis` and feed `direction` (workpiece frame): z the axis, x
/// the feed's part across it ([`tool_frame`]); for a plunge (the feed along the axis) any
/// frame across the axis (the chip is the same all round). `None` for a zero axis.
pub fn frame(axis: &Vector3<f64>, direction: &Vector3<f64>) -> Option<Rotation3<f64>> {
    tool_frame(axis, direction)
        .or_else(|| tool_frame(axis, &axis.cross(&Vector3::x())))
        .or_else(|| tool_frame(axis, &axis.cross(&Vector3::y())))
}

/// The force \[N\] and the wrench about the tip \[N, N m\] (workpiece frame) of `bands` engaged
/// on `cutter` in tool frame `frame`, the tool moving along `direction` with axis `axis` at
/// `feed_per_tooth` \[m\]: the per-revolution average along the edge
/// ([`profile::average`]), the feed per tooth a tool-frame vector
/// ([`profile::tool_feed`]; along the axis for a plunge or a retract).
pub fn edge_wrench(
    coefficients: &Coefficients,
    cutter: &CutterModel,
    frame: &Rotation3<f64>,
    bands: &[Band],
    axis: &Vector3<f64>,
    direction: &Vector3<f64>,
    feed_per_tooth: f64,
) -> Result<(Vector3<f64>, Vector6), TickError> {
    let along = direction.dot(axis);
    let feed = profile::tool_feed(axis, direction, feed_per_tooth)
        .unwrap_or_else(|| Vector3::new(0.0, 0.0, feed_per_tooth * along.signum()));
    let w = profile::average(coefficients, &cutter.profile, &Cut { bands, feed })?;
    let (f, m) = (frame * w.force, frame * w.moment);
    Ok((f, Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)))
}
