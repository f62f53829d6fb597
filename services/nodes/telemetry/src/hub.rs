//! From wire messages to telemetry JSON: conversions, truth matching and
//! the latest state.

use crate::error::TelemetryError;
use crate::latest::TelemetryLatest;
use serde::Serialize;
use spacepose_messages::telemetry::{
    TELEMETRY_SCHEMA_VERSION, TelemetryErrors, TelemetryFilter, TelemetryHealth, TelemetryPose,
    TelemetryTruth, keys,
};
use spacepose_messages::{FilterState, Health, MessageError, PoseEstimate, TruthMsg};
use std::collections::BTreeMap;

/// The stream a JSON sample belongs to (for rate limits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// `pose`.
    Pose,
    /// `filter`.
    Filter,
    /// `health/<instance>`.
    Health,
    /// `truth`.
    Truth,
    /// `errors`.
    Errors,
}

/// One JSON sample to publish on `spacepose/{prefix}/telemetry/{key}`.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// Key suffix (`"pose"`, `"health/tracker-a"`, ...).
    pub key: String,
    /// Its stream.
    pub stream: Stream,
    /// The JSON object (UTF-8).
    pub json: String,
}

fn output<T: Serialize>(key: String, stream: Stream, value: &T) -> Result<Output, TelemetryError> {
    Ok(Output {
        key,
        stream,
        json: serde_json::to_string(value)?,
    })
}

fn invalid(what: &'static str) -> impl FnOnce(MessageError) -> TelemetryError {
    move |source| TelemetryError::InvalidMessage { what, source }
}

/// Converts messages, matches estimates with truth by frame sequence, and
/// keeps the latest state.
#[derive(Debug)]
pub struct TelemetryHub {
    latest: TelemetryLatest,
    window: usize,
    truths: BTreeMap<u64, TruthMsg>,
    /// Estimates waiting for the truth of their frame.
    pending: BTreeMap<u64, Vec<PoseEstimate>>,
}

impl TelemetryHub {
    /// A hub for deployment `prefix`, matching over `window` frames.
    pub fn new(prefix: &str, window: usize) -> Self {
        Self {
            latest: TelemetryLatest {
                schema_version: TELEMETRY_SCHEMA_VERSION,
                prefix: prefix.to_string(),
                ..TelemetryLatest::default()
            },
            window: window.max(1),
            truths: BTreeMap::new(),
            pending: BTreeMap::new(),
        }
    }

    /// The latest state.
    pub fn latest(&self) -> &TelemetryLatest {
        &self.latest
    }

    /// The latest state as JSON (the queryable's answer).
    pub fn latest_json(&self) -> Result<String, TelemetryError> {
        Ok(serde_json::to_string(&self.latest)?)
    }

    /// A pose estimate: its JSON, and its errors when the truth of its frame is known.
    pub fn on_pose(&mut self, m: &PoseEstimate) -> Result<Vec<Output>, TelemetryError> {
        let pose = TelemetryPose::from_wire(m).map_err(invalid("PoseEstimate"))?;
        let mut out = vec![output(keys::POSE.into(), Stream::Pose, &pose)?];
        self.latest.frames.count_pose(&pose);
        self.latest.pose = Some(pose);
        match self.truths.get(&m.sequence) {
            Some(truth) => {
                let truth = *truth;
                out.push(self.errors(m, &truth)?);
            }
            None => {
                self.pending.entry(m.sequence).or_default().push(*m);
                trim(&mut self.pending, self.window);
            }
        }
        Ok(out)
    }

    /// Simulator truth: its JSON, and the errors of the estimates of its
    /// frame that arrived before it.
    pub fn on_truth(&mut self, m: &TruthMsg) -> Result<Vec<Output>, TelemetryError> {
        let truth = TelemetryTruth::from_wire(m).map_err(invalid("TruthMsg"))?;
        let mut out = vec![output(keys::TRUTH.into(), Stream::Truth, &truth)?];
        self.latest.truth = Some(truth);
        self.truths.insert(m.sequence, *m);
        trim(&mut self.truths, self.window);
        for pose in self.pending.remove(&m.sequence).unwrap_or_default() {
            out.push(self.errors(&pose, m)?);
        }
        Ok(out)
    }

    /// A filter state.
    pub fn on_filter(&mut self, m: &FilterState) -> Result<Vec<Output>, TelemetryError> {
        let filter = TelemetryFilter::from_wire(m).map_err(invalid("FilterState"))?;
        let out = output(keys::FILTER.into(), Stream::Filter, &filter)?;
        self.latest.filter = Some(filter);
        Ok(vec![out])
    }

    /// A heartbeat, on `health/<instance>`.
    pub fn on_health(&mut self, m: &Health) -> Result<Vec<Output>, TelemetryError> {
        m.instance.validate().map_err(invalid("Health"))?;
        let health = TelemetryHealth::from_wire(m).map_err(invalid("Health"))?;
        let key = format!("{}/{}", keys::HEALTH, health.instance);
        let out = output(key, Stream::Health, &health)?;
        self.latest.health.insert(health.instance.clone(), health);
        Ok(vec![out])
    }

    /// Errors of `pose` against `truth` of the same frame: angle `d(R̂, R)`
    /// (seed 004 Eq. 12) and position distance.
    fn errors(&mut self, pose: &PoseEstimate, truth: &TruthMsg) -> Result<Output, TelemetryError> {
        let e = TelemetryErrors::from_pose_truth(pose, truth).map_err(invalid("PoseEstimate"))?;
        self.latest.frames.score(&e);
        let out = output(keys::ERRORS.into(), Stream::Errors, &e)?;
        self.latest.errors = Some(e);
        Ok(out)
    }
}

/// Keeps the `window` newest frames of a map keyed by sequence.
fn trim<V>(map: &mut BTreeMap<u64, V>, window: usize) {
    while map.len() > window {
        map.pop_first();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use spacepose_geometry::{Pose, so3};
    use spacepose_messages::{Name, ServiceState, WireStatus};

    fn truth(seq: u64) -> (TruthMsg, Pose) {
        let pose = Pose::new(
            so3::exp(&Vector3::new(0.1 * seq as f64, 0.2, -0.3)),
            Vector3::new(0.2, -0.1, 18.0),
        );
        let mut t = TruthMsg::new();
        t.sequence = seq;
        t.t_s = seq as f64;
        t.set_pose(&pose);
        (t, pose)
    }

    /// An estimate `rot_deg` about x and `dx_m` off the truth of `seq`.
    fn estimate(seq: u64, rot_deg: f64, dx_m: f64, status: WireStatus) -> PoseEstimate {
        let (_, true_pose) = truth(seq);
        let delta = nalgebra::Vector6::new(rot_deg.to_radians(), 0.0, 0.0, dx_m, 0.0, 0.0);
        let mut e = PoseEstimate::new();
        e.sequence = seq;
        e.t_s = seq as f64;
        e.status = status as u8;
        e.instance = Name::new("tracker-a").unwrap();
        e.set_pose(&true_pose.oplus(&delta));
        e.cloud_published_ns = 1_000_000;
        e.published_ns = 3_000_000;
        e.total_ms = 1.5;
        e
    }

    fn json(o: &Output) -> serde_json::Value {
        serde_json::from_str(&o.json).unwrap()
    }

    #[test]
    fn poses_and_truth_are_matched_by_sequence_in_either_order() {
        let mut hub = TelemetryHub::new("demo", 8);
        // Pose first, truth later.
        let out = hub
            .on_pose(&estimate(1, 2.0, 0.03, WireStatus::Tracking))
            .unwrap();
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].key, "pose");
        assert_eq!(json(&out[0])["sequence"], 1);
        let out = hub.on_truth(&truth(1).0).unwrap();
        assert_eq!(
            out.iter().map(|o| o.key.as_str()).collect::<Vec<_>>(),
            ["truth", "errors"]
        );
        let e = json(&out[1]);
        assert!(
            (e["ang_err_deg"].as_f64().unwrap() - 2.0).abs() < 1e-6,
            "{e}"
        );
        assert!(
            (e["pos_err_cm"].as_f64().unwrap() - 3.0).abs() < 1e-6,
            "{e}"
        );
        assert!((e["latency_ms"].as_f64().unwrap() - 2.0).abs() < 1e-9);
        // Truth first, pose later.
        hub.on_truth(&truth(2).0).unwrap();
        let out = hub
            .on_pose(&estimate(2, 1.0, 0.01, WireStatus::Tracking))
            .unwrap();
        assert_eq!(out[1].key, "errors");
        assert!((json(&out[1])["ang_err_deg"].as_f64().unwrap() - 1.0).abs() < 1e-6);
        // A pose of a frame without truth produces no errors.
        let out = hub
            .on_pose(&estimate(3, 1.0, 0.0, WireStatus::Lost))
            .unwrap();
        assert_eq!(out.len(), 1);
        let f = &hub.latest().frames;
        assert_eq!((f.poses, f.tracking, f.lost, f.scored), (3, 2, 1, 2));
        assert!((f.mean_ang_err_deg.unwrap() - 1.5).abs() < 1e-6);
        assert!((f.max_pos_err_cm.unwrap() - 3.0).abs() < 1e-6);
    }

    #[test]
    fn lost_frames_are_reported_but_not_scored() {
        let mut hub = TelemetryHub::new("demo", 8);
        hub.on_truth(&truth(5).0).unwrap();
        let out = hub
            .on_pose(&estimate(5, 40.0, 1.0, WireStatus::Lost))
            .unwrap();
        assert_eq!(json(&out[1])["status"], "lost");
        assert_eq!(hub.latest().frames.scored, 0);
        assert_eq!(hub.latest().frames.mean_ang_err_deg, None);
    }

    #[test]
    fn memory_is_bounded_by_the_window() {
        let mut hub = TelemetryHub::new("demo", 4);
        for k in 0..100 {
            hub.on_pose(&estimate(k, 0.0, 0.0, WireStatus::Tracking))
                .unwrap();
            hub.on_truth(&truth(1000 + k).0).unwrap();
        }
        assert!(hub.pending.len() <= 4 && hub.truths.len() <= 4);
    }

    #[test]
    fn health_goes_per_instance_and_latest_has_everything() {
        let mut hub = TelemetryHub::new("demo", 8);
        let latest: serde_json::Value = serde_json::from_str(&hub.latest_json().unwrap()).unwrap();
        assert!(latest["pose"].is_null() && latest["health"].as_object().unwrap().is_empty());
        for instance in ["tracker-a", "filter"] {
            let mut h = Health::new(Name::new("x").unwrap(), Name::new(instance).unwrap(), 42);
            h.state = ServiceState::Running as u8;
            let out = hub.on_health(&h).unwrap();
            assert_eq!(out[0].key, format!("health/{instance}"));
            assert_eq!(json(&out[0])["state"], "running");
        }
        let mut f = FilterState::new();
        f.initialized = 1;
        hub.on_filter(&f).unwrap();
        hub.on_pose(&estimate(7, 0.0, 0.0, WireStatus::Degraded))
            .unwrap();
        let latest: serde_json::Value = serde_json::from_str(&hub.latest_json().unwrap()).unwrap();
        assert_eq!(latest["prefix"], "demo");
        assert_eq!(latest["pose"]["status"], "degraded");
        assert_eq!(latest["filter"]["initialized"], true);
        assert_eq!(latest["health"]["filter"]["pid"], 42);
        assert_eq!(latest["frames"]["degraded"], 1);
        assert!(latest["truth"].is_null());
    }

    #[test]
    fn bad_messages_are_errors() {
        let mut hub = TelemetryHub::new("demo", 8);
        let mut e = estimate(1, 0.0, 0.0, WireStatus::Tracking);
        e.status = 7;
        assert!(hub.on_pose(&e).is_err());
        let mut t = truth(1).0;
        t.q_sensor_target = [0.0; 4];
        assert!(hub.on_truth(&t).is_err());
        let mut h = Health::new(Name::new("x").unwrap(), Name::new("y").unwrap(), 1);
        h.instance.0[5] = b'/';
        assert!(hub.on_health(&h).is_err());
        assert_eq!(hub.latest().frames.poses, 0);
    }
}
