//! A predicted tool's cut: its samples joined into chords (a fixed-axis sweep per chord,
//! the axis along the great circle when it turns) as long as every sample in between stays
//! within [`super::CHORD_TOLERANCE`] of the chord, the tip and the tool's far end alike. A
//! cut per sample would cost the footprint of the tool each time; the deflection varies
//! slowly along a cut, so a chord spans many samples.

use alloc::vec::Vec;

use nalgebra::Vector3;

use super::CHORD_TOLERANCE;
use crate::error::TickError;
use crate::machining::dexel::{DexelTool, Dexels};
use crate::machining::kinematics::ToolPose;
use crate::machining::program::slerp;

/// Most samples one chord holds back (the check of a new sample costs one step per held
/// sample).
const MAX_HELD: usize = 64;

/// The chord held back: its start, the samples since, the tool cutting it.
#[derive(Debug, Clone, Default)]
pub(super) struct Chord {
    start: Option<ToolPose>,
    held: Vec<ToolPose>,
    tool: Option<(u32, DexelTool)>,
    /// Rays the cuts changed.
    pub rays: usize,
}

/// The distance of `p` from the chord `a -> b` at the parameter nearest it, and that
/// parameter in `[0, 1]`.
fn off_chord(a: &Vector3<f64>, b: &Vector3<f64>, p: &Vector3<f64>) -> (f64, f64) {
    let d = b - a;
    let l2 = d.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((a + d * t - p).norm(), t)
}

impl Chord {
    /// Whether every held sample lies within the tolerance of the chord `start -> end`.
    fn holds(&self, start: &ToolPose, end: &ToolPose, reach: f64) -> bool {
        self.held.iter().all(|h| {
            let (e, t) = off_chord(&start.tip, &end.tip, &h.tip);
            let axis = slerp(&start.axis, &end.axis, t);
            let far = start.tip + (end.tip - start.tip) * t + axis * reach;
            e <= CHORD_TOLERANCE && (far - (h.tip + h.axis * reach)).norm() <= CHORD_TOLERANCE
        })
    }

    /// The tool `solid` (number `number`) at `pose`: extends the chord, or cuts it and starts
    /// the next.
    pub fn to(
        &mut self,
        stock: &mut Dexels,
        solid: &DexelTool,
        number: u32,
        pose: &ToolPose,
    ) -> Result<(), TickError> {
        if self.tool.is_some_and(|(n, _)| n != number) {
            self.flush(stock)?;
            self.start = None;
        }
        self.tool = Some((number, *solid));
        let Some(start) = self.start else {
            self.start = Some(*pose);
            return Ok(());
        };
        let reach = solid.length() + solid.radius_at(solid.length());
        let last = self.held.last().copied();
        if self.held.len() < MAX_HELD && self.holds(&start, pose, reach) {
            self.held.push(*pose);
            return Ok(());
        }
        // Cut to the last sample that held, and start the next chord there.
        if let Some(end) = last {
            self.rays += stock
                .cut(solid, &start.tip, &start.axis, &end.tip, &end.axis)?
                .rays;
            self.start = Some(end);
            self.held.clear();
        }
        self.held.push(*pose);
        Ok(())
    }

    /// Cuts the chord held back.
    pub fn flush(&mut self, stock: &mut Dexels) -> Result<(), TickError> {
        if let (Some(start), Some(end), Some((_, solid))) =
            (self.start, self.held.last().copied(), self.tool)
        {
            self.rays += stock
                .cut(&solid, &start.tip, &start.axis, &end.tip, &end.axis)?
                .rays;
            self.start = Some(end);
        }
        self.held.clear();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machining::cutting::Tool;
    use crate::machining::profile::{Profile, ToolShape};

    #[test]
    fn chords_cut_what_the_moves_cut() {
        let t = Tool::new(0.01, 2, 0.0).unwrap();
        let solid = DexelTool::new(&Profile::new(&t, ToolShape::Ball).unwrap(), 0.03).unwrap();
        let block = || {
            Dexels::block(
                Vector3::new(-0.01, -0.02, -0.01),
                Vector3::new(0.03, 0.02, 0.0),
                5e-4,
            )
            .unwrap()
        };
        let a = Vector3::new(-0.3634127, 0.0, 0.9316282).normalize();
        let pts = [
            Vector3::new(0.0, -0.01, 0.005),
            Vector3::new(0.0, -0.01, -0.0023),
            Vector3::new(0.02, -0.01, 0.0017),
            Vector3::new(0.02, -0.008, 0.0017),
            Vector3::new(0.0, -0.008, -0.0023),
        ];
        let mut exact = block();
        let mut chorded = block();
        let mut c = Chord::default();
        for w in pts.windows(2) {
            let _ = exact.cut(&solid, &w[0], &a, &w[1], &a).unwrap();
            for k in 0..=100 {
                let p = w[0] + (w[1] - w[0]) * (k as f64 / 100.0);
                c.to(&mut chorded, &solid, 1, &ToolPose { tip: p, axis: a })
                    .unwrap();
            }
        }
        c.flush(&mut chorded).unwrap();
        let (pts, missing) = exact.surface_deviation(&chorded, 5e-3).unwrap();
        let worst = pts.iter().map(|p| p.deviation.abs()).fold(0.0, f64::max);
        assert_eq!(missing, 0);
        assert!(worst < 1e-9, "{worst}");
    }
}
