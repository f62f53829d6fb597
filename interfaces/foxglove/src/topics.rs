//! Channel topics and coordinate frames of a recording.
//!
//! Frames: `sensor` is the lidar frame (z boresight); `target` is the
//! target body frame at the newest estimate, `target_truth` at the
//! simulator's truth. A transform `sensor -> target` is `t_sensor_target`.

/// Raw clouds (`foxglove.PointCloud`).
pub const RAW_CLOUD: &str = "/spacepose/raw_cloud";
/// Header of each raw cloud (JSON [`crate::CloudHeaderRecord`]).
pub const RAW_CLOUD_HEADER: &str = "/spacepose/raw_cloud/header";
/// Cropped clouds (`foxglove.PointCloud`).
pub const CLOUD: &str = "/spacepose/cloud";
/// Header of each cropped cloud (JSON [`crate::CloudHeaderRecord`]).
pub const CLOUD_HEADER: &str = "/spacepose/cloud/header";
/// Pose estimates (`foxglove.PoseInFrame`, frame `sensor`).
pub const POSE: &str = "/spacepose/pose";
/// Pose estimates with status and quality (JSON `TelemetryPose`).
pub const POSE_ESTIMATE: &str = "/spacepose/pose/estimate";
/// The last estimates, oldest first (`foxglove.PosesInFrame`, frame
/// `sensor`): live view only.
pub const TRAJECTORY: &str = "/spacepose/pose/trajectory";
/// `sensor -> target` at each estimate (`foxglove.FrameTransform`).
pub const POSE_TF: &str = "/spacepose/pose/tf";
/// Filter states (JSON `TelemetryFilter`).
pub const FILTER_STATE: &str = "/spacepose/filter_state";
/// Pose of initialised filter states (`foxglove.PoseInFrame`).
pub const FILTER_POSE: &str = "/spacepose/filter_state/pose";
/// Acquisitions (JSON [`crate::AcquisitionRecord`]).
pub const ACQUISITION: &str = "/spacepose/acquisition";
/// Heartbeats (JSON `TelemetryHealth`).
pub const HEALTH: &str = "/spacepose/health";
/// Simulator truth (`foxglove.PoseInFrame`).
pub const TRUTH: &str = "/truth";
/// `sensor -> target_truth` (`foxglove.FrameTransform`).
pub const TRUTH_TF: &str = "/truth/tf";
/// Simulator truth with rates (JSON `TelemetryTruth`).
pub const TRUTH_STATE: &str = "/truth/state";
/// The target model in frames `target` and `target_truth` (`foxglove.SceneUpdate`).
pub const SCENE: &str = "/spacepose/scene";

/// The lidar frame.
pub const SENSOR_FRAME: &str = "sensor";
/// The target body frame at the estimated pose.
pub const TARGET_FRAME: &str = "target";
/// The target body frame at the true pose.
pub const TARGET_TRUTH_FRAME: &str = "target_truth";
