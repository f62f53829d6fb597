//! The scan's times and the rate a two-pose scan measured.

use crate::error::TrackError;
use nalgebra::Vector3;
use spacepose_geometry::{Pose, so3};
use spacepose_registration::{Registration, ScanTimes};
use std::time::Instant;

/// The angular velocity (target frame, rad/s) over a scan fitted with two
/// poses: `Log(R_sᵀ R_e) / Δt` of `t_sensor_target` at its start and end.
pub(crate) fn scan_rate(
    t_target_sensor_start: Option<&Pose>,
    registration: &Registration,
    scan: &ScanTimes,
) -> Option<Vector3<f64>> {
    let start = t_target_sensor_start?.inverse();
    let end = registration.t_sensor_target();
    let dt = scan.end_s - scan.start_s;
    (dt > 0.0).then(|| so3::log(&(start.rotation.inverse() * end.rotation)) / dt)
}

pub(crate) fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// Rejects non-finite or reversed scan times, and a scan that does not end
/// after the previous one (`previous_end_s`).
pub(super) fn check_scan_times(
    start_s: f64,
    end_s: f64,
    previous_end_s: f64,
) -> Result<(), TrackError> {
    if start_s.is_finite() && end_s.is_finite() && start_s <= end_s && end_s > previous_end_s {
        Ok(())
    } else {
        Err(TrackError::InvalidScanTimes {
            start_s,
            end_s,
            previous_end_s: Some(previous_end_s),
        })
    }
}
