//! [`RelativeMotionFilter`]: the position Kalman filter and the attitude IEKF
//! of seed 000 §3.2 behind one clock.
//!
//! The two sub-filters are independent (the cross-covariance between the
//! rotation and translation parts of a registration is dropped): the rotation
//! block of the measurement covariance goes to the attitude filter, the
//! translation block to the position filter.
//!
//! The state is only changed by [`RelativeMotionFilter::initialize`] and
//! [`RelativeMotionFilter::update`]; [`RelativeMotionFilter::predict_at`]
//! propagates a copy to any time at or after the last update.

use crate::attitude::{AttitudeFilter, AttitudeNoise, Matrix9};
use crate::config::FilterConfig;
use crate::error::FilterError;
use crate::kalman::checked_covariance;
pub use crate::kalman::covariance_from_information;
use crate::position::PositionFilter;
use nalgebra::{Matrix3, Matrix6, Vector3};
use spacepose_geometry::Pose;

// The outputs keep their old path, `spacepose_filter::filter::*`.
pub use crate::outputs::{Prediction, UpdateOutcome};

#[derive(Debug, Clone, Copy, PartialEq)]
struct State {
    t: f64,
    position: PositionFilter,
    attitude: AttitudeFilter,
}

/// A measurement checked against the prediction, ready to be fused.
struct Pending {
    predicted: State,
    n_rot: Matrix3<f64>,
    n_pos: Matrix3<f64>,
    measured: Pose,
    outcome: UpdateOutcome,
}

/// Constant-velocity relative-motion filter (seed 000 §3.2).
#[derive(Debug, Clone, PartialEq)]
pub struct RelativeMotionFilter {
    config: FilterConfig,
    state: Option<State>,
    consecutive_rejections: u32,
}

impl RelativeMotionFilter {
    /// An uninitialised filter. Fails if the configuration is invalid.
    pub fn new(config: FilterConfig) -> Result<Self, FilterError> {
        config.validate()?;
        Ok(Self {
            config,
            state: None,
            consecutive_rejections: 0,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &FilterConfig {
        &self.config
    }

    /// True once [`Self::initialize`] has succeeded (and until [`Self::reset`]).
    pub fn is_initialized(&self) -> bool {
        self.state.is_some()
    }

    /// Time of the current estimate (s), if initialised.
    pub fn time(&self) -> Option<f64> {
        self.state.map(|s| s.t)
    }

    /// Forgets the state.
    pub fn reset(&mut self) {
        self.state = None;
        self.consecutive_rejections = 0;
    }

    /// Starts (or restarts) the filter at time `t` with the pose
    /// `t_sensor_target`, the velocity `v_sensor` and the angular velocity
    /// `w_target` (pass zeros when unknown, as in seed 000 §5.2). The initial
    /// covariance is diagonal, from the `initial_sigma_*` of the config.
    pub fn initialize(
        &mut self,
        t: f64,
        t_sensor_target: &Pose,
        v_sensor: Vector3<f64>,
        w_target: Vector3<f64>,
    ) -> Result<(), FilterError> {
        if !t.is_finite() {
            return Err(FilterError::NonFinite {
                what: "initial time",
            });
        }
        if !t_sensor_target.is_finite() {
            return Err(FilterError::NonFinite {
                what: "initial pose",
            });
        }
        let c = &self.config;
        let p_pos = diag6(c.initial_sigma_pos_m, c.initial_sigma_v_mps);
        let mut p_att = Matrix9::zeros();
        for i in 0..3 {
            p_att[(i, i)] = c.initial_sigma_rot_deg.to_radians().powi(2);
            p_att[(i + 3, i + 3)] = c.initial_sigma_w_degps.to_radians().powi(2);
            p_att[(i + 6, i + 6)] = c.initial_sigma_w_sensor_degps.to_radians().powi(2);
        }
        let position = PositionFilter::new(t_sensor_target.translation, v_sensor, p_pos)?;
        // The sensor frame's rate starts at 0: the given rate is all the
        // target's (ω = u).
        let attitude = AttitudeFilter::new(
            t_sensor_target.rotation,
            w_target,
            Vector3::zeros(),
            p_att,
            c.sensor_rate,
        )?;
        self.state = Some(State {
            t,
            position,
            attitude,
        });
        self.consecutive_rejections = 0;
        Ok(())
    }

    /// Replaces the whole state with `state` (e.g. the `FilterState` the
    /// filter service published): the estimate and both covariances at time
    /// `state.t`. Used by a tracker that keeps a local copy of the
    /// authoritative filter. Fails on non-finite values or covariances that
    /// are not symmetric positive semi-definite.
    pub fn restore(&mut self, state: &Prediction) -> Result<(), FilterError> {
        if !state.t.is_finite() {
            return Err(FilterError::NonFinite {
                what: "restored time",
            });
        }
        let position = PositionFilter::new(
            state.pose.translation,
            state.v_sensor,
            state.position_covariance,
        )?;
        let attitude = AttitudeFilter::new(
            state.pose.rotation,
            state.w_target,
            state.w_inertial_sensor,
            state.attitude_covariance,
            self.config.sensor_rate,
        )?;
        self.state = Some(State {
            t: state.t,
            position,
            attitude,
        });
        self.consecutive_rejections = 0;
        Ok(())
    }

    /// The estimate at the time of the last update (or initialisation).
    pub fn estimate(&self) -> Result<Prediction, FilterError> {
        let s = self.state.ok_or(FilterError::NotInitialized)?;
        Ok(to_prediction(&s))
    }

    /// The prediction at time `t ≥` [`Self::time`] (Eq. 8, 9). Does not change
    /// the filter. `t` before the current estimate is an error.
    pub fn predict_at(&self, t: f64) -> Result<Prediction, FilterError> {
        Ok(to_prediction(&self.predict_state(t)?))
    }

    fn predict_state(&self, t: f64) -> Result<State, FilterError> {
        let s = self.state.ok_or(FilterError::NotInitialized)?;
        if !t.is_finite() {
            return Err(FilterError::NonFinite {
                what: "prediction time",
            });
        }
        let dt = t - s.t;
        if dt < 0.0 {
            return Err(FilterError::InvalidTimeStep { dt_s: dt });
        }
        let c = &self.config;
        Ok(State {
            t,
            position: s.position.predict(dt, c.q_pos)?,
            attitude: s.attitude.predict(
                dt,
                &AttitudeNoise {
                    q_rot: c.q_rot,
                    q_w: c.q_w,
                    q_w_sensor: c.q_w_sensor,
                },
            )?,
        })
    }

    /// Fuses the registration result `measured_pose` (`t_sensor_target` at
    /// time `t`, strictly after the current estimate) if it passes the
    /// innovation gate. `measurement_covariance` is the registration's 6x6
    /// covariance (`δ = [rot; trans]`, left ⊕ of Eq. 5; see
    /// [`covariance_from_information`]); with `None`, or when the config
    /// says so, the fixed noise `sigma_rot_deg`/`sigma_pos_m` is used.
    ///
    /// A measurement outside the gate is *reported*, not fused
    /// (`accepted = fused = false`, state unchanged): the caller decides
    /// whether to drop it, to [`Self::force_update`] or to re-initialise.
    pub fn update(
        &mut self,
        t: f64,
        measured_pose: &Pose,
        measurement_covariance: Option<Matrix6<f64>>,
    ) -> Result<UpdateOutcome, FilterError> {
        let pending = self.check(t, measured_pose, measurement_covariance.as_ref())?;
        if pending.outcome.accepted {
            self.fuse(pending)
        } else {
            self.consecutive_rejections += 1;
            Ok(UpdateOutcome {
                consecutive_rejections: self.consecutive_rejections,
                ..pending.outcome
            })
        }
    }

    /// Like [`Self::update`] but fuses the measurement whatever the gate says
    /// (`accepted` still reports the gate's verdict).
    pub fn force_update(
        &mut self,
        t: f64,
        measured_pose: &Pose,
        measurement_covariance: Option<Matrix6<f64>>,
    ) -> Result<UpdateOutcome, FilterError> {
        let pending = self.check(t, measured_pose, measurement_covariance.as_ref())?;
        self.fuse(pending)
    }

    /// The innovation of a measurement against the prediction at `t`,
    /// without fusing it. Its `mahalanobis2` is the NIS: χ²(6) when the
    /// measurement covariance (as the filter scales it) and the filter's
    /// own are consistent.
    ///
    /// # Errors
    /// As [`Self::update`].
    pub fn innovation(
        &self,
        t: f64,
        measured_pose: &Pose,
        measurement_covariance: Option<&Matrix6<f64>>,
    ) -> Result<UpdateOutcome, FilterError> {
        Ok(self
            .check(t, measured_pose, measurement_covariance)?
            .outcome)
    }

    fn fuse(&mut self, mut p: Pending) -> Result<UpdateOutcome, FilterError> {
        p.predicted
            .attitude
            .update(&p.measured.rotation, &p.n_rot)?;
        p.predicted
            .position
            .update(&p.measured.translation, &p.n_pos)?;
        self.state = Some(p.predicted);
        self.consecutive_rejections = 0;
        Ok(UpdateOutcome {
            fused: true,
            consecutive_rejections: 0,
            ..p.outcome
        })
    }

    /// Predicts to `t`, computes the innovations and applies the gate.
    fn check(
        &self,
        t: f64,
        measured: &Pose,
        covariance: Option<&Matrix6<f64>>,
    ) -> Result<Pending, FilterError> {
        let s = self.state.ok_or(FilterError::NotInitialized)?;
        if !t.is_finite() {
            return Err(FilterError::NonFinite {
                what: "measurement time",
            });
        }
        if t - s.t <= 0.0 {
            return Err(FilterError::InvalidTimeStep { dt_s: t - s.t });
        }
        if !measured.is_finite() {
            return Err(FilterError::NonFinite {
                what: "measured pose",
            });
        }
        let (n_rot, n_pos, used_registration_covariance) = self.measurement_noise(covariance)?;
        let predicted = self.predict_state(t)?;
        let inn_rot = predicted.attitude.innovation(&measured.rotation, &n_rot)?;
        let inn_pos = predicted
            .position
            .innovation(&measured.translation, &n_pos)?;
        let mahalanobis2 = inn_rot.mahalanobis2()? + inn_pos.mahalanobis2()?;
        let gate = self.config.gate_mahalanobis2;
        let outcome = UpdateOutcome {
            innovation_rot_deg: inn_rot.residual.norm().to_degrees(),
            innovation_pos_m: inn_pos.residual.norm(),
            mahalanobis2,
            gate_mahalanobis2: gate,
            accepted: gate.is_none_or(|g| mahalanobis2 <= g),
            fused: false,
            used_registration_covariance,
            consecutive_rejections: self.consecutive_rejections,
        };
        Ok(Pending {
            predicted,
            n_rot,
            n_pos,
            measured: *measured,
            outcome,
        })
    }

    /// The (rotation, translation) noise blocks and whether they came from
    /// the registration.
    fn measurement_noise(
        &self,
        covariance: Option<&Matrix6<f64>>,
    ) -> Result<(Matrix3<f64>, Matrix3<f64>, bool), FilterError> {
        let c = &self.config;
        match covariance {
            Some(cov) if c.use_registration_covariance => {
                let scaled = cov * c.registration_covariance_scale;
                let n_rot = checked_covariance(
                    &scaled.fixed_view::<3, 3>(0, 0).into_owned(),
                    "measurement covariance (rotation block)",
                )?;
                let n_pos = checked_covariance(
                    &scaled.fixed_view::<3, 3>(3, 3).into_owned(),
                    "measurement covariance (translation block)",
                )?;
                Ok((n_rot, n_pos, true))
            }
            _ => {
                let s_rot = c.sigma_rot_deg.to_radians();
                let n_rot = Matrix3::identity() * (s_rot * s_rot);
                let n_pos = Matrix3::identity() * (c.sigma_pos_m * c.sigma_pos_m);
                Ok((n_rot, n_pos, false))
            }
        }
    }
}

/// Block-diagonal `diag(a² I₃, b² I₃)`.
fn diag6(a: f64, b: f64) -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    for i in 0..3 {
        m[(i, i)] = a * a;
        m[(i + 3, i + 3)] = b * b;
    }
    m
}

fn to_prediction(s: &State) -> Prediction {
    let mut covariance = Matrix6::zeros();
    covariance
        .fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&s.attitude.covariance.fixed_view::<3, 3>(0, 0));
    covariance
        .fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&s.position.covariance.fixed_view::<3, 3>(0, 0));
    Prediction {
        t: s.t,
        pose: Pose::new(s.attitude.r_sensor_target, s.position.p_sensor),
        v_sensor: s.position.v_sensor,
        w_target: s.attitude.w_target,
        w_inertial_sensor: s.attitude.w_inertial_sensor,
        covariance,
        attitude_covariance: s.attitude.covariance,
        position_covariance: s.position.covariance,
    }
}

#[cfg(test)]
#[path = "filter_tests.rs"]
mod tests;
