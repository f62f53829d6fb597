//! The service's configuration file (keys in `deploy/examples/filter.toml`).

use crate::failover::FailoverPolicy;
use serde::{Deserialize, Serialize};
use spacepose_filter::FilterConfig;
use spacepose_runtime::ServiceConfig;

/// Configuration of the `spacepose-filter` service (TOML).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterServiceConfig {
    /// Filter tuning. The default turns the innovation gate off, as the
    /// tracker's own filter does: the registration covariance is
    /// over-confident, and the tracker already rejects inconsistent frames
    /// (they arrive as `degraded` and are not fused).
    pub filter: FilterConfig,
    /// Period of the `FilterState` heartbeat (ms), so late joiners (a
    /// restarted tracker, telemetry) get the state without waiting for an
    /// update. 0 disables it.
    pub state_period_ms: u64,
    /// Frames remembered by the one-estimate-per-frame selector.
    pub selector_window: usize,
    /// The primary tracker instance of a redundant deployment (e.g.
    /// `"tracker-a"`); every other instance is a standby. None: the first
    /// estimate of each frame wins. A swap command changes it at run time.
    pub primary: Option<String>,
    /// Per-frame deadline (ms after the cloud's publication by ingest): a
    /// primary estimate later than this is replaced by a standby's.
    pub frame_deadline_ms: f64,
    /// Sticky failover: after the acting primary missed its deadline on
    /// this many consecutive frames, the standby that replaced it is
    /// promoted (its estimates are then taken without waiting). 0: never.
    /// Default 2 (see [`crate::failover`]).
    pub promote_after_misses: u32,
    /// The displaced primary takes the role back after this many
    /// consecutive frames with a good estimate on time. 0: never (the
    /// promoted standby stays primary). Default 5.
    pub revert_after_frames: u32,
    /// A `tracking` estimate further than this from the filter's
    /// prediction (deg) is inconsistent: a standby's is preferred.
    pub max_disagreement_deg: f64,
    /// Same, on the position (m).
    pub max_disagreement_m: f64,
    /// File the state is persisted to after every change, and restored
    /// from at start when fresh (a restarted filter resumes with its
    /// predecessor's pose, rates and covariances). `spacepose up` sets
    /// `{run dir}/{instance}.filterstate`. None: no snapshot.
    pub snapshot_file: Option<std::path::PathBuf>,
    /// A snapshot written longer ago than this (s, wall clock) is ignored.
    pub snapshot_max_age_s: f64,
    /// When uninitialised (no fresh snapshot, no acquisition yet), start
    /// from the first `tracking` estimate the selector chooses, with zero
    /// rates and the initial covariance of `filter` (as an acquisition
    /// does, seed 000 §5.2), instead of waiting for the next acquisition.
    pub init_from_tracking: bool,
}

impl Default for FilterServiceConfig {
    fn default() -> Self {
        Self {
            filter: FilterConfig::default(),
            state_period_ms: 500,
            selector_window: 64,
            primary: None,
            frame_deadline_ms: 100.0,
            promote_after_misses: FailoverPolicy::default().promote_after_misses,
            revert_after_frames: FailoverPolicy::default().revert_after_frames,
            max_disagreement_deg: 10.0,
            max_disagreement_m: 0.5,
            snapshot_file: None,
            snapshot_max_age_s: 10.0,
            init_from_tracking: true,
        }
    }
}

impl FilterServiceConfig {
    /// The failover policy of the selector.
    pub fn failover(&self) -> FailoverPolicy {
        FailoverPolicy {
            promote_after_misses: self.promote_after_misses,
            revert_after_frames: self.revert_after_frames,
        }
    }
}

impl ServiceConfig for FilterServiceConfig {
    /// Checks every value (NaN fails); the message names the key.
    fn validate(&self) -> Result<(), String> {
        self.filter.validate().map_err(|e| e.to_string())?;
        if self.selector_window == 0 {
            return Err("selector_window must be >= 1".into());
        }
        let positive = [
            ("frame_deadline_ms", self.frame_deadline_ms),
            ("max_disagreement_deg", self.max_disagreement_deg),
            ("max_disagreement_m", self.max_disagreement_m),
            ("snapshot_max_age_s", self.snapshot_max_age_s),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} = {v} must be finite and > 0"));
            }
        }
        if let Some(p) = &self.primary
            && spacepose_messages::Name::new(p).is_err()
        {
            return Err(format!("primary = {p:?} is not an instance name"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The documented example parses and shows the library defaults.
    #[test]
    fn the_deploy_example_is_valid() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../deploy/examples/filter.toml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let c: FilterServiceConfig = toml::from_str(&text).unwrap();
        c.filter.validate().unwrap();
        c.validate().unwrap();
        // The example's [filter] section leaves the gate out: the default.
        assert_eq!(c.filter.gate_mahalanobis2, Some(22.46));
        assert_eq!(c.filter, FilterServiceConfig::default().filter);
        let d = FilterConfig::default();
        assert_eq!(c.filter.q_pos, d.q_pos);
        assert_eq!(
            c.filter.registration_covariance_scale,
            d.registration_covariance_scale
        );
    }

    #[test]
    fn selector_settings_are_validated() {
        for bad in [
            FilterServiceConfig {
                frame_deadline_ms: 0.0,
                ..FilterServiceConfig::default()
            },
            FilterServiceConfig {
                max_disagreement_deg: f64::NAN,
                ..FilterServiceConfig::default()
            },
            FilterServiceConfig {
                primary: Some("no spaces allowed".into()),
                ..FilterServiceConfig::default()
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        let c: FilterServiceConfig =
            toml::from_str("primary = \"tracker-a\"\nframe_deadline_ms = 80.0\n").unwrap();
        assert_eq!(c.primary.as_deref(), Some("tracker-a"));
        c.validate().unwrap();
        assert_eq!(c.failover(), FailoverPolicy::default());
        let c: FilterServiceConfig =
            toml::from_str("promote_after_misses = 3\nrevert_after_frames = 0\n").unwrap();
        assert_eq!(
            c.failover(),
            FailoverPolicy {
                promote_after_misses: 3,
                revert_after_frames: 0
            }
        );
        assert!(toml::from_str::<FilterServiceConfig>("primery = \"a\"\n").is_err());
        let e = FilterServiceConfig {
            snapshot_max_age_s: f64::NAN,
            ..FilterServiceConfig::default()
        }
        .validate()
        .unwrap_err();
        assert!(e.contains("snapshot_max_age_s"), "{e}");
    }
}
