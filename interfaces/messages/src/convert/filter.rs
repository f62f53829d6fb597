//! Conversions between the filter's types and the wire messages of
//! `spacepose-messages` (`FilterState`, `PoseEstimate`, `AcquisitionResult`).
//!
//! The `FilterState` carries the full state of [`RelativeMotionFilter`]
//! (pose, `v_sensor`, `w_target`, `w_inertial_sensor`, the 9x9 attitude and
//! 6x6 position covariances), so a tracker can
//! [`RelativeMotionFilter::restore`] it and predict to any time itself
//! (seed 000 Eq. 8-9).

use super::{matrix_from_wire, matrix_to_wire, vector3_from_wire, vector3_to_wire};
use crate::error::MessageError;
use crate::{AcquisitionResult, FilterState, PoseEstimate, WireStatus};
use nalgebra::{Matrix6, Vector3};
use spacepose_filter::{Prediction, RelativeMotionFilter};
use spacepose_geometry::Pose;

/// A pose measurement taken from a tracker's [`PoseEstimate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Time of validity (s, sensor clock).
    pub t: f64,
    /// Measured `t_sensor_target`.
    pub t_sensor_target: Pose,
    /// Covariance of the left ⊕ perturbation `[rot; trans]`; `None` when the
    /// message carries zeros (unknown: the filter then uses its fixed noise).
    pub covariance: Option<Matrix6<f64>>,
    /// Track status reported by the tracker.
    pub status: WireStatus,
}

fn invalid(what: &'static str, reason: impl ToString) -> MessageError {
    MessageError::InvalidMessage {
        what,
        reason: reason.to_string(),
    }
}

fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// The wire state of a prediction (or estimate): `initialized = 1`, update
/// counter `sequence`; `published_ns` is stamped by the publisher.
pub fn state_from_prediction(p: &Prediction, sequence: u64) -> FilterState {
    let mut s = FilterState::new();
    s.initialized = 1;
    s.sequence = sequence;
    s.t_s = p.t;
    s.set_pose(&p.pose);
    s.v_sensor = vector3_to_wire(&p.v_sensor);
    s.w_target = vector3_to_wire(&p.w_target);
    s.w_inertial_sensor = vector3_to_wire(&p.w_inertial_sensor);
    s.attitude_covariance = matrix_to_wire(&p.attitude_covariance);
    s.position_covariance = matrix_to_wire(&p.position_covariance);
    s
}

/// The wire state of a filter: its estimate, or an uninitialised state.
pub fn state_of(filter: &RelativeMotionFilter, sequence: u64) -> FilterState {
    match filter.estimate() {
        Ok(p) => state_from_prediction(&p, sequence),
        Err(_) => FilterState {
            sequence,
            ..FilterState::new()
        },
    }
}

/// The prediction carried by a wire state; `Ok(None)` when the sender was
/// not initialised. Non-finite values or a bad quaternion are an error.
pub fn prediction_from_state(s: &FilterState) -> Result<Option<Prediction>, MessageError> {
    const WHAT: &str = "FilterState";
    if s.initialized == 0 {
        return Ok(None);
    }
    if !s.t_s.is_finite() {
        return Err(invalid(WHAT, "time is not finite"));
    }
    let pose = s.pose().map_err(|e| invalid(WHAT, e))?;
    if !finite(&s.v_sensor)
        || !finite(&s.w_target)
        || !finite(&s.w_inertial_sensor)
        || !finite(s.attitude_covariance.as_flattened())
        || !finite(s.position_covariance.as_flattened())
    {
        return Err(invalid(WHAT, "non-finite velocity or covariance"));
    }
    let attitude_covariance = matrix_from_wire(&s.attitude_covariance);
    let position_covariance = matrix_from_wire(&s.position_covariance);
    let mut covariance = Matrix6::zeros();
    covariance
        .fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&attitude_covariance.fixed_view::<3, 3>(0, 0));
    covariance
        .fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&position_covariance.fixed_view::<3, 3>(0, 0));
    Ok(Some(Prediction {
        t: s.t_s,
        pose,
        v_sensor: vector3_from_wire(&s.v_sensor),
        w_target: vector3_from_wire(&s.w_target),
        w_inertial_sensor: vector3_from_wire(&s.w_inertial_sensor),
        covariance,
        attitude_covariance,
        position_covariance,
    }))
}

/// The measurement in a tracker estimate. An all-zero covariance means
/// "unknown" (`covariance = None`).
pub fn measurement_from_estimate(e: &PoseEstimate) -> Result<Measurement, MessageError> {
    const WHAT: &str = "PoseEstimate";
    let status = e.wire_status().map_err(|err| invalid(WHAT, err))?;
    if !e.t_s.is_finite() {
        return Err(invalid(WHAT, "time is not finite"));
    }
    let t_sensor_target = e.pose().map_err(|err| invalid(WHAT, err))?;
    let flat = e.covariance.as_flattened();
    if !finite(flat) {
        return Err(invalid(WHAT, "covariance is not finite"));
    }
    let covariance = flat
        .iter()
        .any(|&v| v != 0.0)
        .then(|| matrix_from_wire(&e.covariance));
    Ok(Measurement {
        t: e.t_s,
        t_sensor_target,
        covariance,
        status,
    })
}

/// The initial pose of a successful acquisition (`Ok(None)` when it failed,
/// or when the record confirms an earlier acquisition instead of starting a
/// track: [`AcquisitionResult::confirms`]).
pub fn acquisition_pose(a: &AcquisitionResult) -> Result<Option<(f64, Pose)>, MessageError> {
    const WHAT: &str = "AcquisitionResult";
    if a.success == 0 || a.confirms().is_some() {
        return Ok(None);
    }
    if !a.t_s.is_finite() {
        return Err(invalid(WHAT, "time is not finite"));
    }
    let pose = a.pose().map_err(|e| invalid(WHAT, e))?;
    Ok(Some((a.t_s, pose)))
}

/// Zero velocities, for an initialisation that does not know the rates
/// (seed 000 §5.2: the filter starts at ω = 0).
pub fn zero_rates() -> (Vector3<f64>, Vector3<f64>) {
    (Vector3::zeros(), Vector3::zeros())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Verification;
    use spacepose_filter::FilterConfig;
    use spacepose_geometry::so3;

    fn filter() -> RelativeMotionFilter {
        let mut f = RelativeMotionFilter::new(FilterConfig::default()).unwrap();
        let pose = Pose::new(
            so3::exp(&Vector3::new(0.3, -0.2, 1.1)),
            Vector3::new(0.5, -0.4, 20.0),
        );
        f.initialize(
            3.0,
            &pose,
            Vector3::new(0.01, 0.0, -0.1),
            Vector3::new(0.0, 0.1, 0.05),
        )
        .unwrap();
        let later = pose.oplus(&nalgebra::Vector6::new(0.01, 0.0, 0.0, 0.0, 0.02, 0.0));
        f.update(4.0, &later, None).unwrap();
        f
    }

    #[test]
    fn filter_states_round_trip_through_the_wire() {
        let f = filter();
        let est = f.estimate().unwrap();
        let wire = state_of(&f, 7);
        assert_eq!((wire.initialized, wire.sequence), (1, 7));
        let back = prediction_from_state(&wire).unwrap().unwrap();
        assert_eq!(back.t, est.t);
        let (angle, dist) = back.pose.error_to(&est.pose);
        assert!(angle < 1e-12 && dist < 1e-12);
        assert!((back.v_sensor - est.v_sensor).norm() < 1e-15);
        assert!((back.w_target - est.w_target).norm() < 1e-15);
        assert!((back.covariance - est.covariance).abs().max() < 1e-18);
        assert_eq!(back.attitude_covariance, est.attitude_covariance);
        // A restored filter predicts exactly like the original.
        let mut copy = RelativeMotionFilter::new(FilterConfig::default()).unwrap();
        copy.restore(&back).unwrap();
        let (a, b) = (f.predict_at(5.5).unwrap(), copy.predict_at(5.5).unwrap());
        let (angle, dist) = a.pose.error_to(&b.pose);
        assert!(angle < 1e-12 && dist < 1e-12);
    }

    #[test]
    fn uninitialised_and_broken_states_are_not_predictions() {
        let f = RelativeMotionFilter::new(FilterConfig::default()).unwrap();
        let wire = state_of(&f, 0);
        assert_eq!(wire.initialized, 0);
        assert_eq!(prediction_from_state(&wire).unwrap(), None);
        let mut bad = state_of(&filter(), 1);
        bad.v_sensor[1] = f64::NAN;
        assert!(prediction_from_state(&bad).is_err());
        let mut bad = state_of(&filter(), 1);
        bad.q_sensor_target = [0.0; 4];
        assert!(prediction_from_state(&bad).is_err());
    }

    #[test]
    fn estimates_become_measurements_with_zero_covariance_as_unknown() {
        let mut e = PoseEstimate::new();
        e.t_s = 2.0;
        e.p_sensor_target = [0.0, 0.0, 10.0];
        let m = measurement_from_estimate(&e).unwrap();
        assert_eq!(m.covariance, None);
        assert_eq!(m.status, WireStatus::Tracking);
        e.covariance[0][0] = 1e-4;
        e.covariance[4][4] = 4e-4;
        e.status = WireStatus::Degraded as u8;
        let m = measurement_from_estimate(&e).unwrap();
        let c = m.covariance.unwrap();
        assert_eq!((c[(0, 0)], c[(4, 4)]), (1e-4, 4e-4));
        assert_eq!(m.status, WireStatus::Degraded);
        e.covariance[2][3] = f64::INFINITY;
        assert!(measurement_from_estimate(&e).is_err());
        e.covariance[2][3] = 0.0;
        e.status = 9;
        assert!(measurement_from_estimate(&e).is_err());
    }

    #[test]
    fn only_successful_acquisitions_carry_a_pose() {
        let mut a = AcquisitionResult::new();
        a.t_s = 1.5;
        assert_eq!(acquisition_pose(&a).unwrap(), None);
        a.success = 1;
        let (t, pose) = acquisition_pose(&a).unwrap().unwrap();
        assert_eq!(t, 1.5);
        assert!(pose.translation.norm() == 0.0);
        // A pending acquisition starts a track; a confirmation does not.
        a.verification = Verification::Pending as u8;
        assert!(a.pending() && acquisition_pose(&a).unwrap().is_some());
        a.verification = Verification::Confirms as u8;
        assert_eq!(a.confirms(), Some(a.sequence));
        assert_eq!(acquisition_pose(&a).unwrap(), None);
        a.verification = Verification::Trusted as u8;
        a.t_s = f64::NAN;
        assert!(acquisition_pose(&a).is_err());
    }
}
