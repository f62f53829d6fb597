//! The run directory of a deployment (`$TMPDIR/spacepose/<prefix>/`: configs,
//! per-instance logs, `state.json`) and its state file.

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use spacepose_messages::ServiceKind;
use std::path::{Path, PathBuf};

/// Root of every run directory.
pub fn runs_root() -> PathBuf {
    std::env::temp_dir().join("spacepose")
}

/// Run directory of a prefix.
pub fn run_dir(prefix: &str) -> PathBuf {
    runs_root().join(prefix)
}

/// What `up` started (written to `state.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunState {
    /// Deployment prefix.
    pub prefix: String,
    /// Heartbeat period of the services (ms).
    pub heartbeat_ms: u64,
    /// Start time (s since the Unix epoch).
    pub started_unix_s: f64,
    /// pid of the `spacepose` process that started the suite.
    pub started_by_pid: u32,
    /// pid of the supervising `spacepose` process (`up` leaves one running;
    /// the demo is its own supervisor).
    #[serde(default)]
    pub supervisor_pid: Option<u32>,
    /// The filter's primary tracker instance (redundant deployments).
    #[serde(default)]
    pub primary: Option<String>,
    /// The instances.
    pub instances: Vec<InstanceState>,
}

/// One started instance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InstanceState {
    /// Instance name.
    pub name: String,
    /// Service kind.
    pub kind: ServiceKind,
    /// Process id (also its process group id).
    pub pid: u32,
    /// Binary that was started.
    pub binary: PathBuf,
    /// Log file (stdout and stderr).
    pub log: PathBuf,
    /// `primary` or `standby` for redundant trackers, empty otherwise.
    #[serde(default)]
    pub role: String,
    /// What the supervisor knows: `starting`, `running`, `hung`,
    /// `restarting`, `failed`, `stopping`, `exited`.
    #[serde(default)]
    pub status: String,
    /// Restarts by the supervisor.
    #[serde(default)]
    pub restarts: u32,
    /// Last frame the instance reported in its heartbeat.
    #[serde(default)]
    pub last_frame: Option<u64>,
}

impl RunState {
    /// Path of the state file of `prefix`.
    pub fn path(prefix: &str) -> PathBuf {
        run_dir(prefix).join("state.json")
    }

    /// Writes the state file (atomically: temporary file then rename).
    pub fn save(&self) -> Result<PathBuf> {
        let path = Self::path(&self.prefix);
        let tmp = path.with_extension("json.tmp");
        std::fs::write(&tmp, serde_json::to_string_pretty(self)?)
            .with_context(|| format!("cannot write {}", tmp.display()))?;
        std::fs::rename(&tmp, &path).with_context(|| format!("cannot write {}", path.display()))?;
        Ok(path)
    }

    /// Reads the state file of `prefix`.
    pub fn load(prefix: &str) -> Result<RunState> {
        Self::load_file(&Self::path(prefix))
    }

    fn load_file(path: &Path) -> Result<RunState> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("no running deployment ({} not found)", path.display()))?;
        serde_json::from_str(&text)
            .with_context(|| format!("corrupt state file {}", path.display()))
    }

    /// Every state file under [`runs_root`].
    pub fn all() -> Vec<RunState> {
        let Ok(entries) = std::fs::read_dir(runs_root()) else {
            return Vec::new();
        };
        let mut states: Vec<RunState> = entries
            .flatten()
            .map(|e| e.path().join("state.json"))
            .filter(|p| p.is_file())
            .filter_map(|p| Self::load_file(&p).ok())
            .collect();
        states.sort_by(|a, b| a.prefix.cmp(&b.prefix));
        states
    }

    /// The state of `prefix`, or the only running deployment when `None`.
    pub fn select(prefix: Option<&str>) -> Result<RunState> {
        if let Some(p) = prefix {
            return Self::load(p);
        }
        let all = Self::all();
        match all.len() {
            0 => bail!(
                "no running deployment (no state file under {})",
                runs_root().display()
            ),
            1 => Ok(all.into_iter().next().expect("one state")),
            _ => bail!(
                "several deployments are running ({}): choose one with --prefix",
                all.iter()
                    .map(|s| s.prefix.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }
}

/// Seconds since the Unix epoch.
pub fn unix_now_s() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}
