//! The start-up of `deblur` and `ct-ndt` (issue 25 item 8; not in seed
//! 000).
//!
//! `deblur` compensates each scan with the filter's predicted motion
//! (Eq. 12), but the filter starts at ω = 0 when the rate is unknown (seed
//! 000 §5.2): an acquisition, or the truth in `eval tracking`. At 10°/s and
//! a 1 s scan the first frames are then compensated by nothing while the
//! target turns ~10° within them, and a one-pose fit of a cloud smeared
//! that much lands several degrees off (deos tumbling, development seed 7:
//! 10.6° at frame 2, published as `tracking`); on a design whose surface
//! lets the fit slide, the wrong rate it teaches the filter is never
//! recovered (blind zoo designs 1017 and 1027: ct-ndt 2.3° and 0.6°,
//! deblur 124° and 92°).
//!
//! CT-NDT (Eq. 14) fits the motion within the scan from the points
//! themselves and needs no rate. So while the filter's rate is still too
//! uncertain to compensate a scan (*the start-up*):
//! - a `deblur` frame is fitted as `ct-ndt` fits it;
//! - in both modes the registration may run to
//!   `TrackerConfig::start_up_max_iterations` (CT-NDT starts these frames
//!   up to a scan's turn off and needed 32-50 iterations on development
//!   seeds 7 and 13, where 20 left it 4.0° and 4.3° off);
//! - from the second tracked scan on, CT-NDT's guess for the scan end is
//!   the filter's pose at the scan start turned by the rate the last
//!   CT-NDT scan measured (its start and end poses), not by the filter's
//!   rate of zero. The filter itself learns the rate from the published
//!   poses only, as the filter service does.
//!
//! "Too uncertain" is measured in the unit that matters to the
//! compensation: the blur the rate's uncertainty would leave,
//! `σ_ω,max · (t_end − t_start)` (the largest axis of the filter's ω
//! covariance times the scan's duration, in degrees). It is an angle, free
//! of the target's size, and is compared to
//! `TrackerConfig::start_up_blur_deg` (0: no start-up, the paper's modes).

use crate::config::TrackerConfig;
use crate::mode::TrackingMode;
use spacepose_filter::Prediction;
use spacepose_registration::ScanTimes;

/// The blur (deg, 1σ, largest axis) that the filter's angular-rate
/// uncertainty at `prediction` leaves over `scan`.
pub(crate) fn rate_blur_deg(prediction: &Prediction, scan: &ScanTimes) -> f64 {
    let cov_w = prediction
        .attitude_covariance
        .fixed_view::<3, 3>(3, 3)
        .into_owned();
    let cov_w = (cov_w + cov_w.transpose()) * 0.5;
    let largest = cov_w.symmetric_eigenvalues().max().max(0.0);
    largest.sqrt().to_degrees() * (scan.end_s - scan.start_s).max(0.0)
}

/// True while the filter's rate is too uncertain to compensate `scan`
/// (`start_up_blur_deg` > 0 and the rate blur above it): the
/// start-up, in `deblur` and in `ct-ndt` mode alike.
pub(crate) fn rate_unknown(c: &TrackerConfig, prediction: &Prediction, scan: &ScanTimes) -> bool {
    let bound = c.start_up_blur_deg;
    bound > 0.0 && rate_blur_deg(prediction, scan) > bound
}

/// How a frame is fitted, decided once per frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct FramePlan {
    /// The registration: the configured mode's, except a `deblur` frame in
    /// the start-up, which gets `ct-ndt`'s.
    pub(crate) mode: TrackingMode,
    /// In the start-up: a mode that uses the prediction, and the rate
    /// unknown ([`rate_unknown`]).
    pub(crate) start_up: bool,
}

/// The plan of a frame ending `scan` with the filter at `prediction`.
pub(crate) fn frame_plan(
    c: &TrackerConfig,
    prediction: &Prediction,
    scan: &ScanTimes,
) -> FramePlan {
    let start_up = c.mode.uses_prediction() && rate_unknown(c, prediction, scan);
    let mode = if start_up && c.mode == TrackingMode::Deblur {
        TrackingMode::CtNdt
    } else {
        c.mode
    };
    FramePlan { mode, start_up }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix6, Vector3};
    use spacepose_geometry::Pose;

    fn prediction(sigma_w_deg_s: [f64; 3]) -> Prediction {
        let mut attitude_covariance = spacepose_filter::Matrix9::identity() * 1e-6;
        for (i, s) in sigma_w_deg_s.iter().enumerate() {
            attitude_covariance[(3 + i, 3 + i)] = s.to_radians().powi(2);
        }
        Prediction {
            t: 1.0,
            pose: Pose::identity(),
            v_sensor: Vector3::zeros(),
            w_target: Vector3::zeros(),
            w_inertial_sensor: nalgebra::Vector3::zeros(),
            covariance: Matrix6::identity(),
            attitude_covariance,
            position_covariance: Matrix6::identity(),
        }
    }

    const SCAN: ScanTimes = ScanTimes {
        start_s: 0.0,
        end_s: 0.5,
    };

    #[test]
    fn the_blur_is_the_largest_rate_sigma_over_the_scan() {
        let b = rate_blur_deg(&prediction([0.1, 4.0, 0.2]), &SCAN);
        assert!((b - 2.0).abs() < 1e-9, "{b}");
    }

    #[test]
    fn deblur_fits_by_ct_ndt_until_the_rate_is_known() {
        let c = TrackerConfig::default();
        let bound = c.start_up_blur_deg;
        assert!(bound > 0.0);
        let unknown = prediction([30.0; 3]);
        let known = prediction([0.5 * bound / 0.5; 3]);
        let plan = frame_plan(&c, &unknown, &SCAN);
        assert_eq!((plan.mode, plan.start_up), (TrackingMode::CtNdt, true));
        let plan = frame_plan(&c, &known, &SCAN);
        assert_eq!((plan.mode, plan.start_up), (TrackingMode::Deblur, false));
        // Off, and the other modes: their own registration.
        let off = TrackerConfig {
            start_up_blur_deg: 0.0,
            ..c.clone()
        };
        let plan = frame_plan(&off, &unknown, &SCAN);
        assert_eq!((plan.mode, plan.start_up), (TrackingMode::Deblur, false));
        // ct-ndt keeps its registration and has a start-up; ndt and icp
        // have none.
        let ct = frame_plan(
            &TrackerConfig::with_mode(TrackingMode::CtNdt),
            &unknown,
            &SCAN,
        );
        assert_eq!((ct.mode, ct.start_up), (TrackingMode::CtNdt, true));
        for mode in [TrackingMode::Ndt, TrackingMode::Icp] {
            let plan = frame_plan(&TrackerConfig::with_mode(mode), &unknown, &SCAN);
            assert_eq!((plan.mode, plan.start_up), (mode, false));
        }
    }
}
