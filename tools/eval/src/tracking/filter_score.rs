//! The filter service's posterior, scored (issue 25 item 5: the filter's
//! own consistency). After each frame the deployed filter node holds the
//! state the tracker's next prediction starts from; its pose is compared
//! with the truth and its NEES taken with the filter's own covariance.
//! The attitude IEKF and the position Kalman filter are separate filters
//! (seed 000 §3.2), so the pose covariance is block-diagonal: the attitude
//! block of `[rot; ω]` and the position block of `[p; v]`, in the left ⊕
//! convention of the published covariance ([`super::nees`]). Truth only
//! scores: this runs in the eval, never in the suite.

use super::bounds::pose_error;
use super::nees::pose_nees;
use nalgebra::Rotation3;
use spacepose_geometry::Pose;
use spacepose_messages::FilterState;
use spacepose_messages::convert::prediction_from_state;

/// How far the state's time may be from the frame's scan end (s) to count
/// as this frame's posterior; an older state means the frame was not fused.
const SAME_TIME_S: f64 = 1e-6;

/// The posterior's figures for one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterScore {
    /// Angular error (deg).
    pub ang_err_deg: f64,
    /// Position error (cm).
    pub pos_err_cm: f64,
    /// NEES of the pose with the filter's pose covariance (χ²(6) when
    /// consistent); NaN when that covariance is not positive definite.
    pub nees: f64,
}

impl FilterScore {
    /// All NaN: no posterior at this frame.
    pub const NONE: FilterScore = FilterScore {
        ang_err_deg: f64::NAN,
        pos_err_cm: f64::NAN,
        nees: f64::NAN,
    };
}

/// The filter's posterior at a frame whose scan ends at `scan_end_s`,
/// against `truth` (the symmetric variant nearest it when `symmetries` is
/// not empty); [`FilterScore::NONE`] when the filter did not fuse the frame.
pub fn score(
    state: Option<&FilterState>,
    scan_end_s: f64,
    truth: &Pose,
    symmetries: &[Rotation3<f64>],
) -> FilterScore {
    // The suite's one conversion of the message (a bad state scores NaN).
    let Some(p) = state
        .and_then(|s| prediction_from_state(s).ok().flatten())
        .filter(|p| (p.t - scan_end_s).abs() <= SAME_TIME_S)
    else {
        return FilterScore::NONE;
    };
    let (pose, cov) = (
        p.pose,
        std::array::from_fn(|i| std::array::from_fn(|j| p.covariance[(i, j)])),
    );
    let (ang_deg, pos_m) = pose_error(&pose, truth, symmetries);
    FilterScore {
        ang_err_deg: ang_deg,
        pos_err_cm: pos_m * 100.0,
        nees: pose_nees(&pose, &cov, truth, symmetries).unwrap_or(f64::NAN),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn state(t_s: f64, q: [f64; 4], p: [f64; 3], sigma_rad: f64, sigma_m: f64) -> FilterState {
        let mut s = FilterState::new();
        s.initialized = 1;
        s.t_s = t_s;
        s.q_sensor_target = q;
        s.p_sensor_target = p;
        for i in 0..6 {
            s.attitude_covariance[i][i] = sigma_rad * sigma_rad;
            s.position_covariance[i][i] = sigma_m * sigma_m;
        }
        s
    }

    #[test]
    fn a_posterior_one_sigma_off_on_two_axes_scores_two() {
        let truth = Pose::new(Rotation3::identity(), Vector3::new(0.0, 0.0, 15.0));
        let half = 0.01f64 / 2.0;
        let q = [half.cos(), half.sin(), 0.0, 0.0];
        let s = state(3.0, q, [0.0, 0.02, 15.0], 0.01, 0.02);
        let f = score(Some(&s), 3.0, &truth, &[]);
        assert!((f.nees - 2.0).abs() < 1e-6, "{f:?}");
        assert!((f.ang_err_deg - 0.01f64.to_degrees()).abs() < 1e-9);
        assert!((f.pos_err_cm - 2.0).abs() < 1e-9);
    }

    #[test]
    fn a_state_from_another_time_or_uninitialised_is_not_scored() {
        let truth = Pose::new(Rotation3::identity(), Vector3::zeros());
        let s = state(3.0, [1.0, 0.0, 0.0, 0.0], [0.0; 3], 0.01, 0.02);
        assert!(score(Some(&s), 3.1, &truth, &[]).nees.is_nan());
        assert!(score(None, 3.0, &truth, &[]).ang_err_deg.is_nan());
        let mut u = s;
        u.initialized = 0;
        assert!(score(Some(&u), 3.0, &truth, &[]).pos_err_cm.is_nan());
        let mut bad = s;
        bad.q_sensor_target = [f64::NAN, 0.0, 0.0, 0.0];
        assert!(score(Some(&bad), 3.0, &truth, &[]).nees.is_nan());
    }
}
