//! What ingest takes from the wire: the prediction that centres the crop.

use spacepose_filter::Prediction;
use spacepose_ingest::{AttitudePrediction, TargetPrediction};
use spacepose_messages::convert::{acquisition_pose, prediction_from_state};
use spacepose_messages::{AcquisitionResult, FilterState, MessageError};

/// The filter's position, velocity, attitude and angular velocity, with
/// the worst-axis standard deviations of its attitude and rate; `None`
/// before the filter is initialised.
pub fn from_filter_state(s: &FilterState) -> Result<Option<TargetPrediction>, MessageError> {
    Ok(prediction_from_state(s)?.map(|p| target_prediction(&p)))
}

/// The crop's view of a filter prediction.
pub fn target_prediction(p: &Prediction) -> TargetPrediction {
    TargetPrediction {
        t_s: p.t,
        p_sensor_target: p.pose.translation,
        v_sensor: p.v_sensor,
        attitude: Some(AttitudePrediction {
            r_sensor_target: p.pose.rotation,
            w_target: p.w_target,
            sigma_rot_rad: worst_sigma(&p.attitude_covariance, 0),
            sigma_w_radps: worst_sigma(&p.attitude_covariance, 3),
        }),
    }
}

/// An accepted acquisition gives the position only: its velocities are
/// unknown, so the attitude (which would need ω over the scan) is not used.
/// `None` for a failed acquisition.
pub fn from_acquisition(a: &AcquisitionResult) -> Result<Option<TargetPrediction>, MessageError> {
    Ok(acquisition_pose(a)?.map(|(t_s, pose)| TargetPrediction {
        t_s,
        p_sensor_target: pose.translation,
        v_sensor: nalgebra::Vector3::zeros(),
        attitude: None,
    }))
}

/// Square root of the largest diagonal entry of the 3×3 block starting at
/// `first` of the attitude covariance (the worst-axis standard deviation).
fn worst_sigma(covariance: &spacepose_filter::Matrix9, first: usize) -> f64 {
    (first..first + 3)
        .map(|i| covariance[(i, i)])
        .fold(0.0_f64, f64::max)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix6, Vector3};
    use spacepose_geometry::{Pose, so3};
    use spacepose_messages::convert::state_from_prediction;

    #[test]
    fn a_filter_state_gives_the_attitude_and_its_worst_sigmas() {
        let mut attitude_covariance = spacepose_filter::Matrix9::identity() * 1e-4;
        attitude_covariance[(1, 1)] = 4e-4;
        attitude_covariance[(5, 5)] = 9e-4;
        let p = Prediction {
            t: 3.0,
            pose: Pose::new(
                so3::exp(&Vector3::new(0.1, 0.2, 0.3)),
                Vector3::new(1.0, 2.0, 15.0),
            ),
            v_sensor: Vector3::new(0.1, 0.0, 0.0),
            w_target: Vector3::new(0.0, 0.2, 0.0),
            w_inertial_sensor: Vector3::zeros(),
            covariance: Matrix6::identity(),
            attitude_covariance,
            position_covariance: Matrix6::identity(),
        };
        let t = from_filter_state(&state_from_prediction(&p, 7))
            .unwrap()
            .unwrap();
        let a = t.attitude.unwrap();
        assert_eq!((t.t_s, t.p_sensor_target), (3.0, p.pose.translation));
        assert!((a.sigma_rot_rad - 0.02).abs() < 1e-12);
        assert!((a.sigma_w_radps - 0.03).abs() < 1e-12);
        assert!(from_filter_state(&FilterState::new()).unwrap().is_none());
    }

    #[test]
    fn an_acquisition_gives_the_position_only() {
        let mut a = AcquisitionResult::new();
        a.t_s = 2.0;
        a.set_pose(&Pose::new(
            so3::exp(&Vector3::new(0.0, 0.5, 0.0)),
            Vector3::new(0.0, 0.0, 9.0),
        ));
        assert!(from_acquisition(&a).unwrap().is_none(), "not a success");
        a.success = 1;
        let t = from_acquisition(&a).unwrap().unwrap();
        assert_eq!(t.p_sensor_target, Vector3::new(0.0, 0.0, 9.0));
        assert!(t.attitude.is_none());
        a.t_s = f64::NAN;
        assert!(from_acquisition(&a).is_err());
    }
}
