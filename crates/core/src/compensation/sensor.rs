//! Force/torque sensor processing (VJM paper, section 2.6, Eq. 12-20): the sensor's internal
//! offset, the end effector's weight and centre of gravity, the residual offset as a
//! quadratic polynomial in the quaternion of the sensor orientation, and the transfer of the
//! compensated wrench to the TCP.
//!
//! Model of a reading in the sensor frame S with the sensor at orientation `R_BS` (base from
//! sensor) and gravity `g = (0, 0, -G)` in the base frame (G the end effector's weight \[N\]):
//!
//! ```text
//! F_M = F_SI + R_BS^T g + F_app(q_S) + F_ext
//! M_M = M_SI + r_G x (R_BS^T g) + M_app(q_S) + M_ext
//! ```
//!
//! Eq. 18 removes the weight, the internal offset and the residual polynomial; Eq. 19-20
//! carry the force to the TCP (forces are equal at sensor and TCP; the moment about the TCP
//! loses the lever `r_ST x F`). Eq. 12-15 identify `F_SI, M_SI, G, r_G` from three special
//! orientations; [`crate::identification`] solves the same model by least squares from any
//! three or more orientations (as printed, Eq. 13-15 are not consistent with a rigid-body
//! weight for any orientation set we could reconstruct from Fig. 7, so we implement the model
//! they solve rather than the printed formulas).

use nalgebra::{Isometry3, Rotation3, UnitQuaternion, Vector3};

use crate::error::{BuildError, param};
use crate::vjm::Vector6;

/// Number of terms of the residual polynomial of Eq. 17.
pub const POLY_TERMS: usize = 15;

/// The quaternion of a sensor orientation as the polynomial's input `[w, x, y, z]`, sign
/// fixed so that `w >= 0` (q and -q are one orientation; the polynomial must see one of them).
pub fn orientation_quaternion(r: &UnitQuaternion<f64>) -> [f64; 4] {
    let q = r.quaternion();
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.w, s * q.i, s * q.j, s * q.k]
}

/// The 15 terms of Eq. 17 for quaternion entries `q1..q4`: `1, q1..q4, q1^2..q4^2,
/// q1 q2, q1 q3, q1 q4, q2 q3, q2 q4, q3 q4` (so `F_app = a . terms`).
pub fn poly_terms(q: &[f64; 4]) -> [f64; POLY_TERMS] {
    let [q1, q2, q3, q4] = *q;
    [
        1.0,
        q1,
        q2,
        q3,
        q4,
        q1 * q1,
        q2 * q2,
        q3 * q3,
        q4 * q4,
        q1 * q2,
        q1 * q3,
        q1 * q4,
        q2 * q3,
        q2 * q4,
        q3 * q4,
    ]
}

/// Identified sensor parameters and the fixed sensor-to-TCP transform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorCalibration {
    /// Internal force offset `F_SI` \[N\], sensor frame.
    pub force_offset: Vector3<f64>,
    /// Internal moment offset `M_SI` \[N m\], sensor frame.
    pub moment_offset: Vector3<f64>,
    /// Weight of everything beyond the sensor, `G` \[N\] (> 0; gravity is `-z` of the base).
    pub weight: f64,
    /// Centre of gravity `r_G` \[m\], sensor frame.
    pub center_of_gravity: Vector3<f64>,
    /// Residual-offset polynomial coefficients `a_1..a_15` (Eq. 17) per wrench component
    /// `[Fx, Fy, Fz, Mx, My, Mz]` of the sensor frame; zeros disable it.
    pub residual: [[f64; POLY_TERMS]; 6],
    /// Pose of the TCP in the sensor frame (constructionally known, `^S T_TCP`).
    pub sensor_to_tcp: Isometry3<f64>,
}

impl Default for SensorCalibration {
    fn default() -> Self {
        Self {
            force_offset: Vector3::zeros(),
            moment_offset: Vector3::zeros(),
            weight: 0.0,
            center_of_gravity: Vector3::zeros(),
            residual: [[0.0; POLY_TERMS]; 6],
            sensor_to_tcp: Isometry3::identity(),
        }
    }
}

impl SensorCalibration {
    /// Checks that every value is finite, the weight non-negative and the sensor-to-TCP
    /// rotation a unit quaternion.
    pub fn validate(&self) -> Result<(), BuildError> {
        let vectors: [(&'static str, &[f64]); 3] = [
            ("force_offset", self.force_offset.as_slice()),
            ("moment_offset", self.moment_offset.as_slice()),
            ("center_of_gravity", self.center_of_gravity.as_slice()),
        ];
        for (what, v) in vectors {
            if let Some(index) = v.iter().position(|x| !x.is_finite()) {
                return Err(BuildError::NonFinite { what, index });
            }
        }
        param("weight", self.weight, self.weight >= 0.0, ">= 0 (N)")?;
        if let Some(index) = self.residual.iter().flatten().position(|x| !x.is_finite()) {
            return Err(BuildError::NonFinite {
                what: "residual",
                index,
            });
        }
        let t = &self.sensor_to_tcp;
        if let Some(index) = t
            .translation
            .vector
            .iter()
            .chain(t.rotation.coords.iter())
            .position(|x| !x.is_finite())
        {
            return Err(BuildError::NonFinite {
                what: "sensor_to_tcp",
                index,
            });
        }
        let norm = t.rotation.coords.norm();
        if (norm - 1.0).abs() > 1e-9 {
            return Err(BuildError::InvalidParameter {
                what: "sensor_to_tcp rotation (quaternion norm)",
                value: norm,
                expected: "1 (a rotation)",
            });
        }
        Ok(())
    }

    /// The residual offset `F_app` (Eq. 16-17) at sensor orientation `r_bs`, sensor frame.
    pub fn residual_at(&self, r_bs: &UnitQuaternion<f64>) -> Vector6 {
        let t = poly_terms(&orientation_quaternion(r_bs));
        Vector6::from_fn(|i, _| {
            self.residual
                .get(i)
                .map(|a| a.iter().zip(t.iter()).map(|(a, t)| a * t).sum())
                .unwrap_or(0.0)
        })
    }

    /// What an unloaded sensor reads at orientation `r_bs` (weight + offsets + residual),
    /// sensor frame: the model above with `F_ext = 0`.
    pub fn unloaded_reading(&self, r_bs: &UnitQuaternion<f64>) -> Vector6 {
        let g_s = r_bs.inverse() * Vector3::new(0.0, 0.0, -self.weight);
        let m = self.moment_offset + self.center_of_gravity.cross(&g_s);
        let f = self.force_offset + g_s;
        Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z) + self.residual_at(r_bs)
    }

    /// Eq. 18: the external wrench on the sensor, sensor frame, from a raw reading.
    pub fn compensate(&self, reading: &Vector6, r_bs: &UnitQuaternion<f64>) -> Vector6 {
        reading - self.unloaded_reading(r_bs)
    }

    /// Eq. 19-20: the compensated sensor wrench (sensor frame) as the wrench at the TCP,
    /// expressed in the TCP frame: same force, moment about the TCP `M_S - r_ST x F`, both
    /// rotated by `^TCP R_S`.
    pub fn to_tcp_frame(&self, sensor_wrench: &Vector6) -> Vector6 {
        let f: Vector3<f64> = sensor_wrench.fixed_rows::<3>(0).into_owned();
        let m: Vector3<f64> = sensor_wrench.fixed_rows::<3>(3).into_owned();
        let r_st = self.sensor_to_tcp.translation.vector;
        let m_tcp = m - r_st.cross(&f);
        let r_tcp_s: Rotation3<f64> = self.sensor_to_tcp.rotation.inverse().to_rotation_matrix();
        let (f, m) = (r_tcp_s * f, r_tcp_s * m_tcp);
        Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
    }

    /// The compensated external wrench at the TCP in the base frame (the VJM model's input),
    /// from a raw sensor reading and the TCP pose `tcp` (base frame).
    pub fn tcp_wrench_base(&self, reading: &Vector6, tcp: &Isometry3<f64>) -> Vector6 {
        let r_bs = tcp.rotation * self.sensor_to_tcp.rotation.inverse();
        let w_s = self.compensate(reading, &r_bs);
        let w_tcp = self.to_tcp_frame(&w_s);
        let f = tcp.rotation * w_tcp.fixed_rows::<3>(0).into_owned();
        let m = tcp.rotation * w_tcp.fixed_rows::<3>(3).into_owned();
        Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
    }
}
