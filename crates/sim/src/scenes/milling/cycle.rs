//! The parts of a program run's control cycle ([`super::program::run_program`]): the
//! compensator's step turned into joint offsets, the servo's command per physics step, and
//! the run's own stock with the cutter's engagement in it.

use deflect_core::compensation;
use deflect_core::machining::chip::ChipModel;
use deflect_core::machining::engagement;
use deflect_core::machining::job::{self, Setup};
use deflect_core::machining::path::PathSample;
use deflect_core::machining::stock::{Cutter, ZMap};
use deflect_core::vjm::Vector6;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::arm::MillingArm;
use crate::SimError;

/// What the compensator reads in a cycle.
pub(super) struct CycleInputs<'a> {
    /// Whether the compensator's output is joint offsets (axis-specific compensation).
    pub joint_output: bool,
    /// The joint command \[rad\].
    pub q_cmd: &'a [f64],
    /// The sensor's reading \[N, N m\].
    pub reading: &'a Vector6,
    /// The offline force estimate (pilot control) \[N, N m\].
    pub estimate: &'a Vector6,
    /// The nominal velocity, base frame \[m/s\].
    pub v_nom: &'a Vector3<f64>,
    /// The workpiece placement, the programmed tip \[m\] and the tool orientation.
    pub nominal: (Isometry3<f64>, Vector3<f64>, UnitQuaternion<f64>),
    /// The cycle's nominal joints \[rad\].
    pub q_a: &'a [f64],
}

/// One compensator step: the joint offsets \[rad\] it asks for into `dq_target` (directly
/// axis-specific, else through the rigid IK of the corrected pose).
pub(super) fn correct(
    (c, data): &mut (compensation::Model, compensation::Data),
    cx: &CycleInputs<'_>,
    (arm, ik): (&MillingArm, &mut deflect_core::dalembert::serial::Data),
    dq_target: &mut [f64],
) -> Result<(), SimError> {
    let out = compensation::step(c, data, cx.q_cmd, cx.reading, Some(cx.estimate), cx.v_nom)
        .map_err(|e| SimError::new(format!("compensator step: {e}")))?;
    if cx.joint_output {
        for (dst, src) in dq_target.iter_mut().zip(out.dq.iter()) {
            *dst = *src;
        }
    } else {
        let (to_base, p_nom, tool_orientation) = cx.nominal;
        let dp: Vector3<f64> = out.correction.fixed_rows::<3>(0).into_owned();
        let dr: Vector3<f64> = out.correction.fixed_rows::<3>(3).into_owned();
        let nominal = to_base * Isometry3::from_parts(Translation3::from(p_nom), tool_orientation);
        let target = Isometry3::from_parts(
            Translation3::from(nominal.translation.vector + dp),
            UnitQuaternion::from_scaled_axis(dr) * nominal.rotation,
        );
        let q_target = arm.ik(ik, &target)?;
        for ((d, a), b) in dq_target.iter_mut().zip(&q_target).zip(cx.q_a) {
            *d = a - b;
        }
    }
    Ok(())
}

/// One physics step's joint command: the nominal joints interpolated from `q_a` to `q_b`
/// at `u`, plus the servo's offset lagging behind the correction `dq_servo` \[rad\]; its
/// rate \[rad/s\] over `dt` \[s\].
pub(super) fn servo_command(
    q_cmd: &mut [f64],
    lagged: &mut [f64],
    dq_servo: &[f64],
    (q_a, q_b): (&[f64], &[f64]),
    alpha: f64,
    (u, dt): (f64, f64),
) -> Vec<f64> {
    let q_prev = q_cmd.to_vec();
    for ((((l, m), d), a), b) in lagged
        .iter_mut()
        .zip(q_cmd.iter_mut())
        .zip(dq_servo)
        .zip(q_a)
        .zip(q_b)
    {
        *l += alpha * (d - *l);
        *m = a + (b - a) * u + *l;
    }
    q_cmd
        .iter()
        .zip(&q_prev)
        .map(|(a, b)| (a - b) / dt)
        .collect()
}

/// A run's own stock, cut as its tool moves, and the cutter's engagement with it.
pub(super) struct RunStock {
    /// The stock.
    pub part: ZMap,
    /// The flat cutter.
    pub cutter: Cutter,
    probes: engagement::Probes,
    chip_model: ChipModel,
    chip: engagement::Chip,
    tip_prev: Option<Vector3<f64>>,
}

impl RunStock {
    /// The setup's stock, uncut, and its flat cutter.
    pub(super) fn new(setup: &Setup) -> Result<Self, SimError> {
        let st = &setup.stock;
        let part = ZMap::new(st.min, st.max, st.top, st.cell)
            .map_err(|e| SimError::new(format!("stock: {e}")))?;
        let cutter = Cutter::Flat {
            radius: 0.5 * setup.tool.diameter,
        };
        let probes = engagement::Probes::new(cutter.radius(), st.cell);
        let chip_model = ChipModel::new(&setup.coefficients, &setup.tool, probes.count());
        Ok(Self {
            part,
            cutter,
            probes,
            chip_model,
            chip: engagement::Chip::default(),
            tip_prev: None,
        })
    }

    /// The force \[N\] and wrench \[N, N m\] (workpiece frame) on the tool at `tip` \[m\],
    /// moving along the path at `fz` \[m\] per tooth, and its engagement; then the cut to it.
    #[allow(clippy::type_complexity)]
    pub(super) fn step(
        &mut self,
        tip: &Vector3<f64>,
        path: &PathSample,
        fz: f64,
    ) -> Result<(Vector3<f64>, Vector6, Option<(f64, [f64; 2], usize)>), SimError> {
        let tip = *tip;
        engagement::read(
            &self.part,
            &self.probes,
            &tip,
            &path.direction,
            false,
            &mut self.chip,
        );
        let contact = self.chip.contact();
        let (f, w) = job::chip_wrench(&self.chip_model, &self.chip, &path.direction, fz, false)
            .map_err(|e| SimError::new(format!("program line {}: {e}", path.line)))?;
        let engaged = contact
            .span()
            .map(|a| (a.depth, [a.entry, a.exit], contact.arcs().len()));
        let _ = self
            .part
            .cut(&self.cutter, &self.tip_prev.unwrap_or(tip), &tip)
            .map_err(|e| SimError::new(format!("program line {}: {e}", path.line)))?;
        self.tip_prev = Some(tip);
        Ok((f, w, engaged))
    }
}
