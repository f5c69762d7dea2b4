//! The Delta scene's settings.

use serde::Serialize;

use super::robot::DeltaParams;

/// The scene's settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DeltaOptions {
    /// The robot.
    pub params: DeltaParams,
    /// Peak acceleration of the move \[g\] (5-10 for pick and place).
    pub g: f64,
    /// Start and end of the move, platform centre \[m\].
    pub from: [f64; 3],
    /// End of the move \[m\].
    pub to: [f64; 3],
    /// Speed limit \[m/s\].
    pub v_max: f64,
    /// Time to ramp the acceleration up \[s\] (sets the jerk).
    pub ramp: f64,
    /// Grid of the static tests: lowest corner \[m\].
    pub grid_min: [f64; 3],
    /// Highest corner \[m\].
    pub grid_max: [f64; 3],
    /// Nodes per axis.
    pub nodes: [usize; 3],
    /// Static test force levels along each axis \[N\] (both signs).
    pub test_force: f64,
    /// The corrector's mass parameter m* \[kg\] (platform, payload and the forearms' share).
    pub mass: f64,
    /// Hold after the move \[s\].
    pub tail: f64,
    /// Worker threads.
    pub jobs: usize,
}

impl Default for DeltaOptions {
    /// A 0.3 m move across the workspace at 8 g, a 3 x 3 x 3 grid with +-50 N tests, m* the
    /// platform, payload and half of each forearm.
    fn default() -> Self {
        let params = DeltaParams::default();
        Self {
            mass: params.platform_mass + params.payload_mass + 1.5 * params.forearm_mass,
            params,
            g: 8.0,
            from: [-0.15, -0.05, -0.8],
            to: [0.15, 0.05, -0.75],
            v_max: 4.0,
            ramp: 0.02,
            grid_min: [-0.2, -0.1, -0.85],
            grid_max: [0.2, 0.1, -0.7],
            nodes: [3, 3, 3],
            test_force: 50.0,
            tail: 0.1,
            jobs: 2,
        }
    }
}
