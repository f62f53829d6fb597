//! The replayed run against the recorded one: per frame and tracker, the
//! same status, the same pose bit for bit, or how far apart and why.

use super::recorded::RecordedRun;
use serde::Serialize;
use spacepose_foxglove::AcquisitionRecord;
use spacepose_messages::telemetry::TelemetryPose;
use std::collections::BTreeMap;

/// An acquisition as compared: frame, method, accepted.
pub type AcquisitionKey = (u64, String, bool);

/// How the replay compares with the recording.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Comparison {
    /// Poses in the recording.
    pub recorded_poses: usize,
    /// Poses the replay published.
    pub replayed_poses: usize,
    /// Poses in both (same tracker instance, same frame).
    pub matched: usize,
    /// Of those, the same status.
    pub same_status: usize,
    /// Of those, the same status and bit-identical rotation and position.
    pub identical: usize,
    /// Largest rotation between a recorded and a replayed pose (deg).
    pub max_angle_deg: f64,
    /// Largest distance between a recorded and a replayed position (mm).
    pub max_position_mm: f64,
    /// Recorded frame of the first pose that differs (status or value).
    pub first_difference: Option<u64>,
    /// Frames whose status differs: (recorded frame, recorded status,
    /// replayed status).
    pub status_differences: Vec<(u64, String, String)>,
    /// Recorded poses without a replayed one.
    pub missing_in_replay: usize,
    /// Replayed poses without a recorded one.
    pub extra_in_replay: usize,
    /// The recording's acquisitions.
    pub recorded_acquisitions: Vec<AcquisitionKey>,
    /// The replay's acquisitions (frames in the recording's numbering).
    pub replayed_acquisitions: Vec<AcquisitionKey>,
    /// Where the recording's tracks left `unconfirmed`: (instance, frame of
    /// the first pose after an `unconfirmed` one with another status).
    pub recorded_confirmations: Vec<(String, u64)>,
    /// The same for the replay.
    pub replayed_confirmations: Vec<(String, u64)>,
    /// Why the replay differs, when it does.
    pub reasons: Vec<String>,
}

impl Comparison {
    /// True when every recorded pose was replayed identically, with nothing extra.
    pub fn reproduced(&self) -> bool {
        self.recorded_poses > 0
            && self.identical == self.recorded_poses
            && self.extra_in_replay == 0
    }
}

type Key = (String, u64);

fn by_key(poses: &[TelemetryPose]) -> BTreeMap<Key, &TelemetryPose> {
    poses
        .iter()
        .map(|p| ((p.instance.clone(), p.sequence), p))
        .collect()
}

/// The frames on which each instance's track left `unconfirmed` (the
/// confirmation landed, or the track was lost or restarted).
fn confirmations(poses: &BTreeMap<Key, &TelemetryPose>) -> Vec<(String, u64)> {
    let ordered: Vec<_> = poses.iter().collect();
    ordered
        .windows(2)
        .filter(|w| {
            let ((before_key, before), (key, now)) = (w[0], w[1]);
            before_key.0 == key.0 && before.status == "unconfirmed" && now.status != "unconfirmed"
        })
        .map(|w| w[1].0.clone())
        .collect()
}

fn acquisition_keys(list: &[AcquisitionRecord]) -> Vec<AcquisitionKey> {
    list.iter()
        .map(|a| (a.sequence, a.method.clone(), a.accepted))
        .collect()
}

/// The angle (deg) and distance (mm) between two poses; the angle of the
/// relative rotation by `atan2`, accurate near zero (`acos` of a rounded
/// dot product is not), and 0 for equal quaternions (their product can
/// round to a rotation of 1e-14°).
fn apart(a: &TelemetryPose, b: &TelemetryPose) -> (f64, f64) {
    let d: f64 = (0..3)
        .map(|i| (a.p_sensor_target_m[i] - b.p_sensor_target_m[i]).powi(2))
        .sum();
    if a.q_sensor_target == b.q_sensor_target {
        return (0.0, d.sqrt() * 1e3);
    }
    let q = |p: &TelemetryPose| {
        let [w, x, y, z] = p.q_sensor_target;
        nalgebra::Quaternion::new(w, x, y, z)
    };
    let rel = q(a).conjugate() * q(b);
    let angle = 2.0 * rel.imag().norm().atan2(rel.w.abs());
    (angle.to_degrees(), d.sqrt() * 1e3)
}

/// Compares the recorded run with the replayed poses and acquisitions,
/// whose frame `k` is the recording's `k`-th raw cloud.
pub fn compare(
    recorded: &RecordedRun,
    mut poses: Vec<TelemetryPose>,
    mut acquisitions: Vec<AcquisitionRecord>,
) -> Comparison {
    let renumber = |k: u64| {
        usize::try_from(k)
            .ok()
            .and_then(|i| recorded.raw_sequences.get(i).copied())
            .unwrap_or(u64::MAX)
    };
    poses
        .iter_mut()
        .for_each(|p| p.sequence = renumber(p.sequence));
    acquisitions
        .iter_mut()
        .for_each(|a| a.sequence = renumber(a.sequence));
    let rec = by_key(&recorded.poses);
    let rep = by_key(&poses);
    let mut c = Comparison {
        recorded_poses: rec.len(),
        replayed_poses: rep.len(),
        recorded_acquisitions: acquisition_keys(&recorded.acquisitions),
        replayed_acquisitions: acquisition_keys(&acquisitions),
        recorded_confirmations: confirmations(&rec),
        replayed_confirmations: confirmations(&rep),
        ..Comparison::default()
    };
    for (key, r) in &rec {
        let Some(p) = rep.get(key) else {
            c.missing_in_replay += 1;
            continue;
        };
        c.matched += 1;
        let same_status = r.status == p.status;
        let same_pose =
            r.q_sensor_target == p.q_sensor_target && r.p_sensor_target_m == p.p_sensor_target_m;
        c.same_status += usize::from(same_status);
        if !same_status {
            c.status_differences
                .push((key.1, r.status.clone(), p.status.clone()));
        }
        c.identical += usize::from(same_status && same_pose);
        if !(same_status && same_pose) {
            let first = c.first_difference.get_or_insert(key.1);
            *first = (*first).min(key.1);
        }
        let (deg, mm) = apart(r, p);
        c.max_angle_deg = c.max_angle_deg.max(deg);
        c.max_position_mm = c.max_position_mm.max(mm);
    }
    c.extra_in_replay = rep.keys().filter(|k| !rec.contains_key(*k)).count();
    c.reasons = reasons(recorded, &c);
    c
}

/// Why the replay could not reproduce the recording, as far as it shows.
fn reasons(recorded: &RecordedRun, c: &Comparison) -> Vec<String> {
    let mut out = Vec::new();
    if recorded.raw_gaps() > 0 {
        out.push(format!(
            "the recording skips raw clouds at {} places (decimated with raw_cloud_every, \
             or frames lost while recording): the replayed suite saw other frames",
            recorded.raw_gaps()
        ));
    }
    if c.recorded_acquisitions != c.replayed_acquisitions {
        out.push(format!(
            "acquisitions (frame, method, accepted) differ: recorded {:?}, replayed {:?}. \
             init runs beside the tracker, and the frame its result lands on depends on \
             the machine's load, which a replay does not reproduce",
            c.recorded_acquisitions, c.replayed_acquisitions
        ));
    }
    if c.recorded_confirmations != c.replayed_confirmations {
        out.push(format!(
            "the tracks left `unconfirmed` on other frames: recorded {:?}, replayed {:?} \
             (instance, frame). init verifies an acquisition beside the tracker, and the \
             frame its confirmation lands on depends on the machine's load; until then \
             the tracker publishes the same pose as `unconfirmed`",
            c.recorded_confirmations, c.replayed_confirmations
        ));
    }
    if c.missing_in_replay > 0 || c.extra_in_replay > 0 {
        out.push(format!(
            "{} recorded poses were not replayed and {} replayed poses were not recorded: \
             a cloud subscriber buffers 2 frames and overwrites the oldest \
             (CLOUD_BUFFER in interfaces/bus), so a service that falls behind loses \
             frames, and which ones depends on timing",
            c.missing_in_replay, c.extra_in_replay
        ));
    }
    if out.is_empty() && c.identical < c.matched {
        out.push(format!(
            "with the same frames and acquisitions, poses differ from frame {} (by at \
             most {:.1e} deg, {:.1e} mm): the remaining input that depends on timing is \
             the filter service's state, which replaces the tracker's own prediction \
             when it arrives before the next frame (apply_filter_state in \
             services/nodes/tracker/src/track.rs); `spacepose track` on the recording runs them in \
             lockstep and is bit-identical",
            c.first_difference.unwrap_or_default(),
            c.max_angle_deg,
            c.max_position_mm
        ));
    }
    out
}

#[cfg(test)]
#[path = "compare_tests.rs"]
mod tests;
