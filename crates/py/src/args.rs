//! Scalar argument extractors for `#[pyo3(from_py_with = ...)]`, one function per argument
//! name: pyo3 does not tell an extractor which argument it reads, and the `InputError` it
//! raises must name it (`args::count::max_iterations` reads `max_iterations` through
//! [`crate::scalars::count`]). The signatures keep their Python defaults (`max_iterations=10`).

/// Defines `pub mod $module` with one extractor `fn(&Bound<PyAny>) -> PyResult<$ty>` per name.
macro_rules! extractors {
    ($(#[$doc:meta])* $module:ident: $conv:path => $ty:ty { $($name:ident),* $(,)? }) => {
        $(#[$doc])*
        pub mod $module {
            use pyo3::prelude::*;
            $(
                #[doc = concat!("Reads the argument `", stringify!($name), "`.")]
                pub fn $name(o: &Bound<'_, PyAny>) -> PyResult<$ty> {
                    $conv(o, stringify!($name))
                }
            )*
        }
    };
}

extractors!(
    /// Real scalars ([`crate::scalars::real`]).
    real: crate::scalars::real => f64 {
        a_max, arm, base_radius, contact_force, cutoff_hz, dt, edge_angle, extension, forearm,
        half_width, j_max, platform_radius,
        jam_force, jam_margin, link, lowpass_cutoff_hz, mass, max_condition, max_correction,
        max_rate, max_turn, min_motion_fraction, min_sigma, min_step_fraction, orientation_tolerance,
        position_tolerance, ramp, rate_hz, step, threshold, tolerance, torque_deadband,
        v_max, weight,
    }
);

extractors!(
    /// Optional real scalars ([`crate::scalars::opt_real`]).
    opt_real: crate::scalars::opt_real => Option<f64> {
        approach_step, rate_hz, spacing, stop_radius, t, target_force,
    }
);

extractors!(
    /// Counts ([`crate::scalars::count`]).
    count: crate::scalars::count => usize {
        bias_samples, dim, g_level, iterations, max_approach_steps, max_bisections, max_iterations,
        max_jam_steps, max_steps, moving_average_window, n_displacement, n_force, window,
    }
);

extractors!(
    /// Optional counts ([`crate::scalars::opt_count`]).
    opt_count: crate::scalars::opt_count => Option<usize> { n_force }
);

extractors!(
    /// Pairs of reals ([`crate::scalars::pair`]).
    pair: crate::scalars::pair => (f64, f64) { approach_direction }
);

extractors!(
    /// Optional pairs of reals ([`crate::scalars::opt_pair`]).
    opt_pair: crate::scalars::opt_pair => Option<(f64, f64)> { pilot }
);

extractors!(
    /// Triples of reals ([`crate::scalars::triple`]).
    triple: crate::scalars::triple => [f64; 3] { angular, linear }
);

extractors!(
    /// Optional triples of reals ([`crate::scalars::opt_triple`]).
    opt_triple: crate::scalars::opt_triple => Option<[f64; 3]> { gravity }
);

extractors!(
    /// Texts ([`crate::scalars::text`]): a lone surrogate is an `InputError`, not a
    /// `UnicodeEncodeError`.
    text: crate::scalars::text => String { text }
);
