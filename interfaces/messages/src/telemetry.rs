//! JSON schema of the ground-facing zenoh keys (`spacepose/{prefix}/telemetry/*`).
//!
//! These are what `spacepose ground` and any zenoh client (Python's
//! `eclipse-zenoh` included) read: one JSON object per sample, UTF-8, with a
//! `schema_version` field ([`TELEMETRY_SCHEMA_VERSION`]). Frames: `sensor`
//! is the lidar frame (z boresight, x right, y down), `target` the target
//! body frame; `t_sensor_target` maps target-body coordinates to the sensor
//! frame (`x_sensor = R x_target + p`). Quaternions are scalar first
//! `[w, x, y, z]`; Euler angles are 3-2-1 (`R = Rz(yaw) Ry(pitch) Rx(roll)`).
//! Times `t_s` are on the sensor clock; `*_ns` stamps are CLOCK_REALTIME.

use crate::clock::elapsed_ms;
use crate::convert::rotation_from_wxyz;
use crate::error::MessageError;
use crate::health::{Counters, ServiceState};
use crate::pose::{WireStatus, mode_from_code};
use crate::{FilterState, Health, PoseEstimate, TruthMsg};
use serde::{Deserialize, Serialize};
use spacepose_geometry::Euler321;

/// Version of the JSON telemetry schema (bumped on any incompatible change).
pub const TELEMETRY_SCHEMA_VERSION: u16 = 4;

/// Key suffixes below `spacepose/{prefix}/telemetry/`.
pub mod keys {
    /// [`super::TelemetryPose`] stream.
    pub const POSE: &str = "pose";
    /// [`super::TelemetryFilter`] stream.
    pub const FILTER: &str = "filter";
    /// [`super::TelemetryHealth`] stream.
    pub const HEALTH: &str = "health";
    /// [`super::TelemetryTruth`] stream (simulated sources only).
    pub const TRUTH: &str = "truth";
    /// [`super::TelemetryErrors`] stream (simulated sources only).
    pub const ERRORS: &str = "errors";
}

fn euler_deg(q: &[f64; 4]) -> Result<[f64; 3], MessageError> {
    Ok(Euler321::from_rotation(&rotation_from_wxyz(q)?).to_degrees())
}

fn sigmas<const N: usize>(cov: &[[f64; N]; N], start: usize, scale: f64) -> [f64; 3] {
    std::array::from_fn(|i| cov[start + i][start + i].max(0.0).sqrt() * scale)
}

/// `spacepose/{prefix}/telemetry/pose`: one tracker estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TelemetryPose {
    /// [`TELEMETRY_SCHEMA_VERSION`].
    pub schema_version: u16,
    /// Tracker instance (e.g. `"tracker-a"`).
    pub instance: String,
    /// Sequence of the cloud frame the estimate comes from.
    pub sequence: u64,
    /// Time of validity (s, sensor clock; scan end).
    pub t_s: f64,
    /// `"tracking"`, `"degraded"`, `"lost"` or `"unconfirmed"` (tracked,
    /// but the acquisition that started the track awaits its verification).
    pub status: String,
    /// Registration mode: `"ndt"`, `"deblur"`, `"ct-ndt"` or `"icp"`.
    pub mode: String,
    /// Rotation of `t_sensor_target`, unit quaternion `[w, x, y, z]`.
    pub q_sensor_target: [f64; 4],
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor_target_m: [f64; 3],
    /// 3-2-1 Euler angles of `R_sensor_target`, `[yaw, pitch, roll]` (deg).
    pub euler_321_deg: [f64; 3],
    /// 1-σ of the left ⊕ rotation perturbation, about sensor axes x, y, z (deg); 0 = unknown.
    pub sigma_rot_deg: [f64; 3],
    /// 1-σ of the left ⊕ translation perturbation along sensor axes x, y, z (cm); 0 = unknown.
    pub sigma_pos_cm: [f64; 3],
    /// Final registration cost (NDT score or ICP mean squared distance, m²).
    pub cost: f64,
    /// Rotations held by the registration, not measured (0-3): their
    /// uncertainty is in `sigma_rot_deg`.
    pub held_axes: u8,
    /// Translations held by the registration, not measured (0-3): their
    /// uncertainty is in `sigma_pos_cm`.
    pub held_translations: u8,
    /// Registration iterations.
    pub iterations: u32,
    /// Inlier points of the registration.
    pub inliers: u32,
    /// Points used by the registration.
    pub points_used: u32,
    /// Preprocessing time (ms).
    pub preprocess_ms: f64,
    /// Registration time (ms).
    pub registration_ms: f64,
    /// Total tracker compute time (ms).
    pub total_ms: f64,
    /// Cloud published → pose published (ms, wall clock); `null` when unknown.
    pub latency_ms: Option<f64>,
    /// CLOCK_REALTIME when the pose was published (ns since the Unix epoch).
    pub published_ns: i64,
}

impl TelemetryPose {
    /// The JSON view of a wire estimate.
    pub fn from_wire(m: &PoseEstimate) -> Result<Self, MessageError> {
        Ok(Self {
            schema_version: TELEMETRY_SCHEMA_VERSION,
            instance: m.instance.as_str().to_string(),
            sequence: m.sequence,
            t_s: m.t_s,
            status: WireStatus::from_u8(m.status)?.as_str().to_string(),
            mode: mode_from_code(m.mode)?.as_str().to_string(),
            q_sensor_target: m.q_sensor_target,
            p_sensor_target_m: m.p_sensor_target,
            euler_321_deg: euler_deg(&m.q_sensor_target)?,
            sigma_rot_deg: sigmas(&m.covariance, 0, 180.0 / std::f64::consts::PI),
            sigma_pos_cm: sigmas(&m.covariance, 3, 100.0),
            cost: m.cost,
            held_axes: m.held_axes,
            held_translations: m.held_translations,
            iterations: m.iterations,
            inliers: m.inliers,
            points_used: m.points_used,
            preprocess_ms: m.preprocess_ms,
            registration_ms: m.registration_ms,
            total_ms: m.total_ms,
            latency_ms: elapsed_ms(m.cloud_published_ns, m.published_ns),
            published_ns: m.published_ns,
        })
    }
}

/// `spacepose/{prefix}/telemetry/filter`: the fused motion state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TelemetryFilter {
    /// [`TELEMETRY_SCHEMA_VERSION`].
    pub schema_version: u16,
    /// False before the filter is initialised (other fields then meaningless).
    pub initialized: bool,
    /// Filter update counter.
    pub sequence: u64,
    /// Time of validity (s, sensor clock).
    pub t_s: f64,
    /// Rotation of `t_sensor_target`, unit quaternion `[w, x, y, z]`.
    pub q_sensor_target: [f64; 4],
    /// Position of the target origin in the sensor frame (m).
    pub p_sensor_target_m: [f64; 3],
    /// 3-2-1 Euler angles of `R_sensor_target`, `[yaw, pitch, roll]` (deg).
    pub euler_321_deg: [f64; 3],
    /// Velocity of the target origin relative to the sensor, sensor frame (m/s).
    pub v_sensor_m_s: [f64; 3],
    /// Angular velocity of the target relative to the sensor, target body frame (deg/s).
    pub w_target_deg_s: [f64; 3],
    /// 1-σ of the attitude perturbation (deg).
    pub sigma_rot_deg: [f64; 3],
    /// 1-σ of the angular velocity, target body frame (deg/s).
    pub sigma_w_deg_s: [f64; 3],
    /// 1-σ of the position, sensor frame (cm).
    pub sigma_pos_cm: [f64; 3],
    /// 1-σ of the velocity, sensor frame (cm/s).
    pub sigma_vel_cm_s: [f64; 3],
    /// CLOCK_REALTIME when the state was published (ns).
    pub published_ns: i64,
}

impl TelemetryFilter {
    /// The JSON view of a wire filter state.
    pub fn from_wire(m: &FilterState) -> Result<Self, MessageError> {
        let deg = 180.0 / std::f64::consts::PI;
        let euler = if m.initialized == 1 {
            euler_deg(&m.q_sensor_target)?
        } else {
            [0.0; 3]
        };
        Ok(Self {
            schema_version: TELEMETRY_SCHEMA_VERSION,
            initialized: m.initialized == 1,
            sequence: m.sequence,
            t_s: m.t_s,
            q_sensor_target: m.q_sensor_target,
            p_sensor_target_m: m.p_sensor_target,
            euler_321_deg: euler,
            v_sensor_m_s: m.v_sensor,
            w_target_deg_s: m.w_target.map(|w| w * deg),
            sigma_rot_deg: sigmas(&m.attitude_covariance, 0, deg),
            sigma_w_deg_s: sigmas(&m.attitude_covariance, 3, deg),
            sigma_pos_cm: sigmas(&m.position_covariance, 0, 100.0),
            sigma_vel_cm_s: sigmas(&m.position_covariance, 3, 100.0),
            published_ns: m.published_ns,
        })
    }
}

/// `spacepose/{prefix}/telemetry/health`: one heartbeat.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TelemetryHealth {
    /// [`TELEMETRY_SCHEMA_VERSION`].
    pub schema_version: u16,
    /// Service kind (e.g. `"tracker"`).
    pub service: String,
    /// Instance name (e.g. `"tracker-a"`).
    pub instance: String,
    /// `"starting"`, `"running"`, `"degraded"` or `"stopping"`.
    pub state: String,
    /// Process id.
    pub pid: u32,
    /// Heartbeat counter.
    pub sequence: u64,
    /// Time since the service started (s).
    pub uptime_s: f64,
    /// The service's counters (`frames_in`, `frames_out`,
    /// `rejected_non_finite`, `rejected_empty`, `rejected_oversized`,
    /// `rejected_wire`, `errors`, `last_frame`), as top-level keys.
    #[serde(flatten)]
    pub counters: Counters,
    /// CLOCK_REALTIME of the heartbeat (ns).
    pub published_ns: i64,
}

impl TelemetryHealth {
    /// The JSON view of a wire heartbeat.
    pub fn from_wire(m: &Health) -> Result<Self, MessageError> {
        Ok(Self {
            schema_version: TELEMETRY_SCHEMA_VERSION,
            service: m.service.as_str().to_string(),
            instance: m.instance.as_str().to_string(),
            state: ServiceState::from_u8(m.state)?.as_str().to_string(),
            pid: m.pid,
            sequence: m.sequence,
            uptime_s: m.uptime_s,
            counters: m.counters,
            published_ns: m.published_ns,
        })
    }
}

/// `spacepose/{prefix}/telemetry/truth`: simulator truth (simulated sources only).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TelemetryTruth {
    /// [`TELEMETRY_SCHEMA_VERSION`].
    pub schema_version: u16,
    /// Cloud frame sequence.
    pub sequence: u64,
    /// Time of validity (s, sensor clock; scan end).
    pub t_s: f64,
    /// True rotation of `t_sensor_target`, `[w, x, y, z]`.
    pub q_sensor_target: [f64; 4],
    /// True position of the target origin in the sensor frame (m).
    pub p_sensor_target_m: [f64; 3],
    /// 3-2-1 Euler angles of the true `R_sensor_target`, `[yaw, pitch, roll]` (deg).
    pub euler_321_deg: [f64; 3],
    /// True velocity of the target relative to the sensor, sensor frame (m/s).
    pub v_sensor_m_s: [f64; 3],
    /// True angular velocity, target body frame (deg/s).
    pub w_target_deg_s: [f64; 3],
}

impl TelemetryTruth {
    /// The JSON view of a wire truth message.
    pub fn from_wire(m: &TruthMsg) -> Result<Self, MessageError> {
        let deg = 180.0 / std::f64::consts::PI;
        Ok(Self {
            schema_version: TELEMETRY_SCHEMA_VERSION,
            sequence: m.sequence,
            t_s: m.t_s,
            q_sensor_target: m.q_sensor_target,
            p_sensor_target_m: m.p_sensor_target,
            euler_321_deg: euler_deg(&m.q_sensor_target)?,
            v_sensor_m_s: m.v_sensor,
            w_target_deg_s: m.w_target.map(|w| w * deg),
        })
    }
}

/// `spacepose/{prefix}/telemetry/errors`: estimate vs truth for one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TelemetryErrors {
    /// [`TELEMETRY_SCHEMA_VERSION`].
    pub schema_version: u16,
    /// Tracker instance.
    pub instance: String,
    /// Cloud frame sequence.
    pub sequence: u64,
    /// Time of validity (s, sensor clock).
    pub t_s: f64,
    /// Track status of the estimate (`"tracking"`, `"degraded"`, `"lost"`,
    /// `"unconfirmed"`).
    pub status: String,
    /// Rotation angle between estimated and true `R_sensor_target` (deg).
    pub ang_err_deg: f64,
    /// Distance between estimated and true target positions (cm).
    pub pos_err_cm: f64,
    /// Cloud published → pose published (ms, wall clock); `null` when unknown.
    pub latency_ms: Option<f64>,
}

impl TelemetryErrors {
    /// Errors of `pose` against `truth` (same frame expected; not checked).
    pub fn from_pose_truth(pose: &PoseEstimate, truth: &TruthMsg) -> Result<Self, MessageError> {
        let (angle_rad, dist_m) = pose.pose()?.error_to(&truth.pose()?);
        Ok(Self {
            schema_version: TELEMETRY_SCHEMA_VERSION,
            instance: pose.instance.as_str().to_string(),
            sequence: pose.sequence,
            t_s: pose.t_s,
            status: WireStatus::from_u8(pose.status)?.as_str().to_string(),
            ang_err_deg: angle_rad.to_degrees(),
            pos_err_cm: dist_m * 100.0,
            latency_ms: elapsed_ms(pose.cloud_published_ns, pose.published_ns),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Name, TrackingMode};
    use nalgebra::Vector3;
    use spacepose_geometry::{Pose, so3};

    fn estimate() -> PoseEstimate {
        let mut m = PoseEstimate::new();
        m.instance = Name::new("tracker-a").unwrap();
        m.status = WireStatus::Degraded as u8;
        m.mode = TrackingMode::CtNdt.code();
        m.set_pose(&Pose::new(
            Euler321::from_degrees(10.0, 20.0, 30.0).to_rotation(),
            Vector3::new(0.1, 0.2, 20.0),
        ));
        m.covariance[0][0] = (1.0f64.to_radians()).powi(2);
        m.covariance[4][4] = 0.02 * 0.02;
        m.cloud_published_ns = 1_000_000_000;
        m.published_ns = 1_003_500_000;
        m
    }

    #[test]
    fn pose_telemetry_has_units_in_names_and_round_trips_json() {
        let t = TelemetryPose::from_wire(&estimate()).unwrap();
        assert_eq!(t.status, "degraded");
        assert_eq!(t.mode, "ct-ndt");
        assert!((t.euler_321_deg[0] - 10.0).abs() < 1e-9);
        assert!((t.euler_321_deg[2] - 30.0).abs() < 1e-9);
        assert!((t.sigma_rot_deg[0] - 1.0).abs() < 1e-9);
        assert!((t.sigma_pos_cm[1] - 2.0).abs() < 1e-9);
        assert!((t.latency_ms.unwrap() - 3.5).abs() < 1e-9);
        let json = serde_json::to_string(&t).unwrap();
        assert!(json.contains("\"p_sensor_target_m\""));
        let back: TelemetryPose = serde_json::from_str(&json).unwrap();
        // serde_json may round the last bit of a float: compare with a tolerance.
        assert_eq!(
            (&back.instance, &back.status, back.sequence),
            (&t.instance, &t.status, t.sequence)
        );
        for (a, b) in back.q_sensor_target.iter().zip(&t.q_sensor_target) {
            assert!((a - b).abs() < 1e-15);
        }
    }

    #[test]
    fn errors_compare_estimate_and_truth() {
        let est = estimate();
        let mut truth = TruthMsg::new();
        let mut true_pose = est.pose().unwrap();
        true_pose.rotation =
            so3::exp(&Vector3::new(0.0, 0.0, 2f64.to_radians())) * true_pose.rotation;
        true_pose.translation.x += 0.03;
        truth.set_pose(&true_pose);
        let e = TelemetryErrors::from_pose_truth(&est, &truth).unwrap();
        assert!((e.ang_err_deg - 2.0).abs() < 1e-6, "{}", e.ang_err_deg);
        assert!((e.pos_err_cm - 3.0).abs() < 1e-6, "{}", e.pos_err_cm);
    }

    #[test]
    fn bad_codes_are_errors_not_panics() {
        let mut m = estimate();
        m.status = 9;
        assert!(TelemetryPose::from_wire(&m).is_err());
        let mut h = Health::new(Name::new("tracker").unwrap(), Name::new("a").unwrap(), 1);
        assert_eq!(TelemetryHealth::from_wire(&h).unwrap().state, "starting");
        h.state = 200;
        assert!(TelemetryHealth::from_wire(&h).is_err());
        let f = FilterState::new();
        assert!(!TelemetryFilter::from_wire(&f).unwrap().initialized);
    }
}
