//! The truth of a simulated recording, for scoring only: the poses of
//! `truth.csv` (written by `spacepose sim` beside its frames). It never
//! reaches the pipeline.

use crate::truth_csv::HEADER;
use anyhow::{Context, Result, bail};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use spacepose_geometry::Pose;
use std::collections::BTreeMap;
use std::path::Path;

/// `t_sensor_target` at scan end, by frame index.
pub type TruthPoses = BTreeMap<u64, Pose>;

/// The poses of `dir/truth.csv`, or `None` when there is no such file.
pub fn read_dir_truth(dir: &Path) -> Result<Option<TruthPoses>> {
    let path = dir.join("truth.csv");
    if !path.is_file() {
        return Ok(None);
    }
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    parse(&text)
        .with_context(|| format!("parsing {}", path.display()))
        .map(Some)
}

/// Parses a `truth.csv` text (header [`HEADER`]).
fn parse(text: &str) -> Result<TruthPoses> {
    let mut lines = text.lines();
    if lines.next() != Some(HEADER) {
        bail!("the header is not spacepose sim's");
    }
    let mut poses = TruthPoses::new();
    for (n, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let row = || format!("row {}", n + 2);
        let cols: Vec<&str> = line.split(',').collect();
        let num = |i: usize| -> Result<f64> {
            let s = cols
                .get(i)
                .with_context(|| format!("{}: too few columns", row()))?;
            s.parse::<f64>()
                .with_context(|| format!("{}: column {} = {s:?}", row(), i + 1))
        };
        let frame: u64 = cols[0]
            .parse()
            .with_context(|| format!("{}: frame {:?}", row(), cols[0]))?;
        let p = Vector3::new(num(4)?, num(5)?, num(6)?);
        let q = Quaternion::new(num(7)?, num(8)?, num(9)?, num(10)?);
        if !(p.iter().all(|x| x.is_finite()) && (q.norm() - 1.0).abs() < 1e-6) {
            bail!("{}: not a pose", row());
        }
        let rotation = UnitQuaternion::from_quaternion(q).to_rotation_matrix();
        poses.insert(frame, Pose::new(rotation, p));
    }
    Ok(poses)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_give_poses_and_bad_rows_errors() {
        let row = "3,2.0,3.0,100,0.5,0,15,1,0,0,0,0,0,0,0,0,0,0,0,0,15";
        let poses = parse(&format!("{HEADER}\n{row}\n")).expect("parses");
        assert_eq!(poses[&3].translation, Vector3::new(0.5, 0.0, 15.0));
        assert!(parse("frame,x\n").is_err());
        let bad = "3,2.0,3.0,100,0.5,0,15,2,0,0,0,0,0,0,0,0,0,0,0,0,15";
        assert!(parse(&format!("{HEADER}\n{bad}\n")).is_err());
        assert!(parse(&format!("{HEADER}\n3,2.0\n")).is_err());
    }
}
