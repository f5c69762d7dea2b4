//! Orthogonal projection of the correction onto the plane normal to the feed (VJM paper,
//! section 2.4, Eq. 10-11): fewer axis movements and no oscillation along the path.

use nalgebra::Vector3;

/// Feed speeds below this \[m/s\] count as standing still: no feed direction is defined.
pub const MIN_FEED_SPEED: f64 = 1.0e-9;

/// `r_v = r - (r . v_n) v_n` with `v_n = v / |v|` (Eq. 10-11). When the feed speed is below
/// [`MIN_FEED_SPEED`] the correction is returned unchanged and the flag is `false` (no feed
/// direction to remove); otherwise the flag is `true`.
pub fn project_normal_to_feed(r: &Vector3<f64>, v: &Vector3<f64>) -> (Vector3<f64>, bool) {
    let speed = v.norm();
    if speed.is_nan() || speed < MIN_FEED_SPEED {
        return (*r, false);
    }
    let vn = v / speed;
    (r - vn * r.dot(&vn), true)
}
