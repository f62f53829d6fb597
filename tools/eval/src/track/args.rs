//! The command line of `spacepose track`.

use clap::Args;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use spacepose_geometry::Pose;
use spacepose_tracker::TrackingMode;
use std::path::PathBuf;
use std::str::FromStr;

/// How the track starts.
#[derive(Debug, Clone, PartialEq)]
pub enum InitChoice {
    /// The init service's methods on the frames themselves (CNN when the
    /// package has a model, template matching), as the suite acquires.
    Acquire,
    /// A pose the operator gives: `t_sensor_target` at the first frame's
    /// scan end.
    Given(Pose),
}

impl FromStr for InitChoice {
    type Err = String;

    /// `acquire`, or `px,py,pz,qw,qx,qy,qz`: the target's position in the
    /// sensor frame (m) and its attitude (unit quaternion, target → sensor,
    /// normalised here; its norm must be within 1 % of 1).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "acquire" {
            return Ok(InitChoice::Acquire);
        }
        let v = s
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| format!("{s:?}: {e} (expected `acquire` or px,py,pz,qw,qx,qy,qz)"))?;
        let [px, py, pz, qw, qx, qy, qz] = v[..] else {
            return Err(format!(
                "{s:?}: {} numbers; a pose is px,py,pz,qw,qx,qy,qz",
                v.len()
            ));
        };
        if v.iter().any(|x| !x.is_finite()) {
            return Err(format!("{s:?}: every number must be finite"));
        }
        let q = Quaternion::new(qw, qx, qy, qz);
        if (q.norm() - 1.0).abs() > 0.01 {
            return Err(format!(
                "{s:?}: the quaternion's norm is {:.4}, not 1",
                q.norm()
            ));
        }
        let rotation = UnitQuaternion::from_quaternion(q).to_rotation_matrix();
        Ok(InitChoice::Given(Pose::new(
            rotation,
            Vector3::new(px, py, pz),
        )))
    }
}

/// `spacepose track`.
#[derive(Debug, Args)]
pub struct TrackArgs {
    /// The recording: a directory of `frame_NNNNNN.pcd|ply` files, an MCAP
    /// file, or a ROS 2 bag directory (`metadata.yaml` and `*.mcap`).
    #[arg(long)]
    pub input: PathBuf,
    /// Target: a built-in name, a package directory, a mesh file or `zoo:N`.
    #[arg(long, default_value = "deos")]
    pub target: String,
    /// Scale of a mesh file (file units → metres).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Where the poses go: `.csv`, one row per frame, or `.mcap`, the run
    /// as the suite's recorder writes it (clouds, poses, filter states,
    /// acquisitions, the target model; Foxglove schemas).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// How the track starts: `acquire`, or a pose `px,py,pz,qw,qx,qy,qz`
    /// (`t_sensor_target` at the first frame, m).
    #[arg(long, default_value = "acquire", allow_hyphen_values = true)]
    pub init: InitChoice,
    /// Tracking mode (default: the tracker's, or the `--config` file's).
    #[arg(long)]
    pub mode: Option<TrackingMode>,
    /// Point-cloud topic of an MCAP file or bag (default: its only one).
    #[arg(long)]
    pub topic: Option<String>,
    /// TOML file with the tables `input`, `ingest`, `tracker`, `filter` and
    /// `init`, each the service's own configuration (every key optional).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Writes the summary as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Tracks at most this many frames.
    #[arg(long)]
    pub frames: Option<usize>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn init_choices_parse_or_say_why_not() {
        assert_eq!("acquire".parse::<InitChoice>(), Ok(InitChoice::Acquire));
        let Ok(InitChoice::Given(p)) = "0,0,15,1,0,0,0".parse::<InitChoice>() else {
            panic!("a pose");
        };
        assert_eq!(p.translation, Vector3::new(0.0, 0.0, 15.0));
        for bad in ["", "1,2,3", "0,0,15,2,0,0,0", "0,0,nan,1,0,0,0", "a,b"] {
            assert!(bad.parse::<InitChoice>().is_err(), "{bad}");
        }
    }
}
