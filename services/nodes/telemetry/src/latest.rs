//! The latest state, returned as one JSON object by the queryable
//! `spacepose/{prefix}/telemetry/latest`.

use serde::{Deserialize, Serialize};
use spacepose_messages::telemetry::{
    TelemetryErrors, TelemetryFilter, TelemetryHealth, TelemetryPose, TelemetryTruth,
};
use std::collections::BTreeMap;

/// Key suffix of the queryable (below `spacepose/{prefix}/telemetry/`).
pub const LATEST_KEY: &str = "latest";

/// Running figures over the frames seen since telemetry started.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FrameStats {
    /// Pose estimates received (all instances).
    pub poses: u64,
    /// Of which `tracking`.
    pub tracking: u64,
    /// Of which `degraded`.
    pub degraded: u64,
    /// Of which `lost`.
    pub lost: u64,
    /// Of which `unconfirmed`.
    #[serde(default)]
    pub unconfirmed: u64,
    /// Sequence of the newest estimate; `null` before the first.
    pub last_sequence: Option<u64>,
    /// Cloud published → pose published of the newest estimate (ms).
    pub last_latency_ms: Option<f64>,
    /// Tracker compute time of the newest estimate (ms).
    pub last_total_ms: Option<f64>,
    /// Estimates (not `lost`) matched with truth.
    pub scored: u64,
    /// Mean angular error of the scored estimates (deg); `null` when none.
    pub mean_ang_err_deg: Option<f64>,
    /// Mean position error of the scored estimates (cm).
    pub mean_pos_err_cm: Option<f64>,
    /// Largest angular error of the scored estimates (deg).
    pub max_ang_err_deg: Option<f64>,
    /// Largest position error of the scored estimates (cm).
    pub max_pos_err_cm: Option<f64>,
}

impl FrameStats {
    /// Counts one estimate of `status` (`"tracking"`, `"degraded"`,
    /// `"unconfirmed"`; anything else counts `lost`).
    pub fn count_pose(&mut self, p: &TelemetryPose) {
        self.poses += 1;
        match p.status.as_str() {
            "tracking" => self.tracking += 1,
            "degraded" => self.degraded += 1,
            "unconfirmed" => self.unconfirmed += 1,
            _ => self.lost += 1,
        }
        self.last_sequence = Some(p.sequence);
        self.last_latency_ms = p.latency_ms;
        self.last_total_ms = Some(p.total_ms);
    }

    /// Adds a frame's errors to the running mean and maximum (lost frames
    /// are not scored: their pose is only a prediction).
    pub fn score(&mut self, e: &TelemetryErrors) {
        if e.status == "lost" {
            return;
        }
        let n = self.scored as f64;
        let mean = |old: Option<f64>, v: f64| Some((old.unwrap_or(0.0) * n + v) / (n + 1.0));
        self.mean_ang_err_deg = mean(self.mean_ang_err_deg, e.ang_err_deg);
        self.mean_pos_err_cm = mean(self.mean_pos_err_cm, e.pos_err_cm);
        let max = |old: Option<f64>, v: f64| Some(old.map_or(v, |o| o.max(v)));
        self.max_ang_err_deg = max(self.max_ang_err_deg, e.ang_err_deg);
        self.max_pos_err_cm = max(self.max_pos_err_cm, e.pos_err_cm);
        self.scored += 1;
    }
}

/// `spacepose/{prefix}/telemetry/latest` (queryable): the newest sample of
/// every stream in one JSON object; streams never received are `null`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TelemetryLatest {
    /// [`spacepose_messages::telemetry::TELEMETRY_SCHEMA_VERSION`].
    pub schema_version: u16,
    /// Deployment prefix.
    pub prefix: String,
    /// Newest pose estimate (any instance).
    pub pose: Option<TelemetryPose>,
    /// Newest filter state.
    pub filter: Option<TelemetryFilter>,
    /// Newest heartbeat of every instance, by instance name.
    pub health: BTreeMap<String, TelemetryHealth>,
    /// Newest simulator truth (simulated sources only).
    pub truth: Option<TelemetryTruth>,
    /// Newest errors against truth (simulated sources only).
    pub errors: Option<TelemetryErrors>,
    /// Running figures.
    pub frames: FrameStats,
}
