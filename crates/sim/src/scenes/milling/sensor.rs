//! The simulated force/torque sensor at the arm's flange: what it reads under a process force
//! at the tool point, with its internal offsets, the weight of tool and spindle beyond it and
//! seeded Gaussian noise (the reading model of Hähn and Weigold, sec. 2.6, Eq. 12-18).

use deflect_core::compensation::SensorCalibration;
use deflect_core::vjm::Vector6;
use nalgebra::{Isometry3, Vector3};
use serde::Serialize;

use crate::noise::Noise;

/// The simulated flange force/torque sensor.
#[derive(Debug, Clone, Serialize)]
pub struct SensorParams {
    /// Internal force offset \[N\], sensor frame.
    pub force_offset: [f64; 3],
    /// Internal moment offset \[N m\], sensor frame.
    pub moment_offset: [f64; 3],
    /// Weight of tool and spindle beyond the sensor \[N\].
    pub weight: f64,
    /// Their centre of gravity \[m\], sensor frame.
    pub center_of_gravity: [f64; 3],
    /// Noise standard deviation of the forces \[N\] and moments \[N m\].
    pub noise: [f64; 2],
}

impl Default for SensorParams {
    fn default() -> Self {
        Self {
            force_offset: [14.0, -9.0, 22.0],
            moment_offset: [0.8, -0.5, 0.3],
            weight: 180.0,
            center_of_gravity: [0.09, 0.004, -0.006],
            noise: [4.0, 0.3],
        }
    }
}

impl SensorParams {
    /// The true calibration (what identification should find).
    pub fn calibration(&self, sensor_to_tcp: Isometry3<f64>) -> SensorCalibration {
        SensorCalibration {
            force_offset: Vector3::from(self.force_offset),
            moment_offset: Vector3::from(self.moment_offset),
            weight: self.weight,
            center_of_gravity: Vector3::from(self.center_of_gravity),
            sensor_to_tcp,
            ..SensorCalibration::default()
        }
    }

    /// A reading (sensor frame) with the sensor at `sensor` (base frame) under the external
    /// force `force` \[N\] at `tcp` \[m\] (base frame), with noise from `noise` scaled by `scale`.
    pub fn reading(
        &self,
        cal: &SensorCalibration,
        sensor: &Isometry3<f64>,
        tcp: &Vector3<f64>,
        force: &Vector3<f64>,
        noise: &mut Noise,
        scale: f64,
    ) -> Vector6 {
        let r_inv = sensor.rotation.inverse();
        let f = r_inv * force;
        let m = r_inv * (tcp - sensor.translation.vector).cross(force);
        let mut w =
            Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z) + cal.unloaded_reading(&sensor.rotation);
        for (k, v) in w.iter_mut().enumerate() {
            *v += scale * self.noise[usize::from(k >= 3)] * noise.gauss();
        }
        w
    }
}
