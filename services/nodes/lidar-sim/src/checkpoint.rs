//! Where a restarted sensor resumes (issue 7): a small file recording the
//! last frame slot taken.
//!
//! A real sensor that restarts does not replay the frames it missed: it
//! produces the frame that is due now. The simulator's frame `k` is a pure
//! function of `k` (scenario state, random stream), so resuming is choosing
//! `k`. Two ways were considered:
//!
//! - a scenario start instant handed to every instance by the supervisor,
//!   `k = (now - start) / period`: no file, but the supervisor would have to
//!   carry an instant through its descriptor to every (re)start, the first
//!   frames would be skipped whenever the first start is slow (loading the
//!   target), and `rate_hz = 0` (as fast as possible) has no clock at all;
//! - **a checkpoint** of the last frame slot taken (frame index and its wall
//!   time), written before each frame is published: the restart resumes on
//!   the same frame grid at the first slot not in the past,
//!   `k = k_last + max(1, ceil((now - t_last) / period))`, i.e. the frame
//!   now due; frames whose slots passed while it was dead are simply
//!   missing. With `rate_hz = 0` it resumes at `k_last + 1`.
//!
//! The checkpoint is chosen: it is local to the sensor, needs from the
//! supervisor only a file path (as the filter's state snapshot does), and
//! keeps the cadence of the frames across a restart. It is written
//! *before* the frame is published, so a crash between the two loses that
//! frame rather than publishing it twice. A checkpoint of another
//! configuration (fingerprint) or older than `checkpoint_max_age_s` is
//! ignored (with a warning): the sensor then starts at frame 0.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use tracing::{info, warn};

/// First line of a checkpoint file.
const MAGIC: &str = "spacepose-lidar-sim checkpoint v1";

/// The last frame slot a sensor took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Checkpoint {
    /// Frame index.
    pub frame: u64,
    /// Wall time of its slot (ns, CLOCK_REALTIME).
    pub slot_ns: i64,
    /// Fingerprint of the sensor configuration that produced it.
    pub fingerprint: u64,
}

/// Where to resume.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resume {
    /// Frame to publish next.
    pub frame: u64,
    /// Wall time of its slot (ns, CLOCK_REALTIME); may be in the future.
    pub slot_ns: i64,
}

impl Checkpoint {
    /// Reads `path`; `None` when it does not exist. Errors on an unreadable
    /// or corrupt file.
    pub fn load(path: &Path) -> Result<Option<Self>> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
        };
        Self::parse(&text)
            .with_context(|| format!("corrupt checkpoint {}", path.display()))
            .map(Some)
    }

    fn parse(text: &str) -> Result<Self> {
        let mut lines = text.lines();
        if lines.next() != Some(MAGIC) {
            bail!("not a checkpoint (expected {MAGIC:?} first)");
        }
        let (mut frame, mut slot_ns, mut fingerprint) = (None, None, None);
        for line in lines.filter(|l| !l.trim().is_empty()) {
            let Some((key, value)) = line.split_once('=') else {
                bail!("line {line:?}: expected key=value");
            };
            let bad = |e: std::num::ParseIntError| anyhow::anyhow!("{key} = {value:?}: {e}");
            match key {
                "frame" => frame = Some(value.parse::<u64>().map_err(bad)?),
                "slot_ns" => slot_ns = Some(value.parse::<i64>().map_err(bad)?),
                "fingerprint" => {
                    fingerprint = Some(u64::from_str_radix(value, 16).map_err(bad)?);
                }
                _ => bail!("unknown key {key:?}"),
            }
        }
        match (frame, slot_ns, fingerprint) {
            (Some(frame), Some(slot_ns), Some(fingerprint)) => Ok(Self {
                frame,
                slot_ns,
                fingerprint,
            }),
            _ => bail!("frame, slot_ns and fingerprint are all required"),
        }
    }

    /// Writes it to `path` atomically (a temporary file renamed over it).
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = format!(
            "{MAGIC}\nframe={}\nslot_ns={}\nfingerprint={:016x}\n",
            self.frame, self.slot_ns, self.fingerprint
        );
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(".tmp");
        std::fs::write(&tmp, text).with_context(|| format!("cannot write {tmp:?}"))?;
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot rename {tmp:?} to {}", path.display()))
    }

    /// The frame due at `now_ns` on this checkpoint's frame grid
    /// (`period_ns` > 0), or the next one when frames have no clock
    /// (`None`, as fast as possible).
    pub fn resume(&self, now_ns: i64, period_ns: Option<i64>) -> Resume {
        let Some(period) = period_ns.filter(|p| *p > 0) else {
            return Resume {
                frame: self.frame.saturating_add(1),
                slot_ns: now_ns,
            };
        };
        let elapsed = now_ns.saturating_sub(self.slot_ns).max(0);
        // ceil(elapsed / period), at least one slot on.
        let slots = (elapsed / period + i64::from(elapsed % period != 0)).max(1);
        Resume {
            frame: self.frame.saturating_add(slots as u64),
            slot_ns: self.slot_ns.saturating_add(slots.saturating_mul(period)),
        }
    }
}

/// The checkpoint file of one sensor configuration.
#[derive(Debug, Clone)]
pub struct Checkpointer {
    path: PathBuf,
    fingerprint: u64,
    max_age_ns: i64,
}

impl Checkpointer {
    /// The checkpoint at `path` of the configuration whose `Debug` form is
    /// `config`; one older than `max_age_s` is not resumed.
    pub fn new(path: PathBuf, config: &str, max_age_s: f64) -> Self {
        Checkpointer {
            path,
            fingerprint: fingerprint(config),
            max_age_ns: (max_age_s * 1e9) as i64,
        }
    }

    /// Where this instance starts at `now_ns`: frame 0 now, or, after a
    /// restart, the frame due now on its predecessor's frame grid. A
    /// checkpoint of another configuration or too old is reported and
    /// frame 0 taken.
    ///
    /// # Errors
    /// An unreadable or corrupt file (the caller counts it and starts at
    /// [`Resume::fresh`]).
    pub fn starting_point(&self, now_ns: i64, period_ns: Option<i64>) -> Result<Resume> {
        let fresh = Resume::fresh(now_ns);
        let path = self.path.display();
        match Checkpoint::load(&self.path)? {
            None => Ok(fresh),
            Some(c) if c.fingerprint != self.fingerprint => {
                warn!(path = %path, "checkpoint of another configuration ignored: starting at frame 0");
                Ok(fresh)
            }
            Some(c) if now_ns.saturating_sub(c.slot_ns) > self.max_age_ns => {
                warn!(path = %path, frame = c.frame, "checkpoint older than checkpoint_max_age_s ignored: starting at frame 0");
                Ok(fresh)
            }
            Some(c) => {
                let r = c.resume(now_ns, period_ns);
                info!(
                    last_frame = c.frame,
                    resume_frame = r.frame,
                    missed = r.frame - c.frame - 1,
                    due_in_ms = r.slot_ns.saturating_sub(now_ns) as f64 * 1e-6,
                    "restarted: resuming the scenario at the frame now due"
                );
                Ok(r)
            }
        }
    }

    /// Records that frame `frame` takes its slot at `slot_ns`.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn record(&self, frame: u64, slot_ns: i64) -> Result<()> {
        Checkpoint {
            frame,
            slot_ns,
            fingerprint: self.fingerprint,
        }
        .save(&self.path)
    }
}

impl Resume {
    /// Frame 0, due at `now_ns`.
    pub fn fresh(now_ns: i64) -> Self {
        Resume {
            frame: 0,
            slot_ns: now_ns,
        }
    }
}

/// FNV-1a of `text` (a configuration's `Debug` form): a checkpoint is only
/// resumed by the configuration that wrote it.
pub fn fingerprint(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: i64 = 1_000_000;

    fn at(frame: u64, slot_ns: i64) -> Checkpoint {
        Checkpoint {
            frame,
            slot_ns,
            fingerprint: 0xabc,
        }
    }

    #[test]
    fn a_restart_resumes_at_the_frame_now_due_on_the_same_grid() {
        let c = at(16, 1_000 * MS);
        let p = Some(200 * MS);
        // Restarted 350 ms after frame 16's slot: 17's slot passed, 18 is due
        // 50 ms from now.
        assert_eq!(
            c.resume(1_350 * MS, p),
            Resume {
                frame: 18,
                slot_ns: 1_400 * MS
            }
        );
        // Exactly on a slot: that frame.
        assert_eq!(c.resume(1_400 * MS, p).frame, 18);
        // Within the first period (or a clock step back): the next frame.
        assert_eq!(c.resume(1_010 * MS, p).frame, 17);
        assert_eq!(c.resume(900 * MS, p).frame, 17);
        // No clock: the next frame at once.
        assert_eq!(
            c.resume(5_000 * MS, None),
            Resume {
                frame: 17,
                slot_ns: 5_000 * MS
            }
        );
    }

    #[test]
    fn checkpoints_round_trip_and_corrupt_ones_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lidar-sim.sensorstate");
        assert_eq!(Checkpoint::load(&path).unwrap(), None);
        let c = at(42, 1_234_567_890_123);
        c.save(&path).unwrap();
        assert_eq!(Checkpoint::load(&path).unwrap(), Some(c));
        for bad in [
            "",
            "frame=1\n",
            "spacepose-lidar-sim checkpoint v1\nframe=1\nslot_ns=2\n",
            "spacepose-lidar-sim checkpoint v1\nframe=x\nslot_ns=2\nfingerprint=0\n",
            "spacepose-lidar-sim checkpoint v1\nframe=1\nslot_ns=2\nfingerprint=0\nextra=1\n",
        ] {
            std::fs::write(&path, bad).unwrap();
            assert!(Checkpoint::load(&path).is_err(), "{bad:?}");
        }
        assert_ne!(fingerprint("seed: 7"), fingerprint("seed: 8"));
    }

    #[test]
    fn a_checkpointer_resumes_only_its_own_recent_checkpoints() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sim.sensorstate");
        let p = Some(200 * MS);
        let mine = Checkpointer::new(path.clone(), "seed: 7", 1.0);
        assert_eq!(
            mine.starting_point(5 * MS, p).unwrap(),
            Resume::fresh(5 * MS)
        );
        mine.record(16, 1_000 * MS).unwrap();
        assert_eq!(mine.starting_point(1_350 * MS, p).unwrap().frame, 18);
        // Older than max_age: frame 0.
        assert_eq!(
            mine.starting_point(2_001 * MS, p).unwrap(),
            Resume::fresh(2_001 * MS)
        );
        // Another configuration: frame 0.
        let other = Checkpointer::new(path.clone(), "seed: 8", 1.0);
        assert_eq!(other.starting_point(1_350 * MS, p).unwrap().frame, 0);
        std::fs::write(&path, "corrupt").unwrap();
        assert!(mine.starting_point(1_350 * MS, p).is_err());
    }
}
