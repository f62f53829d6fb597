//! The `truth.csv` file written next to simulated frames.
//!
//! One row per frame. Columns (SI units unless the name says otherwise):
//!
//! | column | meaning |
//! |---|---|
//! | `frame` | frame index, matches `frame_NNNNNN.pcd` |
//! | `scan_start_s`, `scan_end_s` | scan interval on the sensor clock (s) |
//! | `points` | points in the frame file |
//! | `px_m`, `py_m`, `pz_m` | target centre of mass in the sensor frame at scan end (m) |
//! | `qw`, `qx`, `qy`, `qz` | attitude of the target body in the sensor frame at scan end (unit quaternion, target → sensor) |
//! | `yaw_deg`, `pitch_deg`, `roll_deg` | the same attitude as 321 Euler angles |
//! | `vx_mps`, `vy_mps`, `vz_mps` | velocity of the centre of mass relative to the sensor, sensor frame (m/s) |
//! | `wx_radps`, `wy_radps`, `wz_radps` | angular velocity of the target relative to the sensor, target body frame (rad/s) |
//! | `range_m` | distance of the centre of mass (m) |

use anyhow::{Context, Result};
use nalgebra::UnitQuaternion;
use spacepose_geometry::Euler321;
use spacepose_scenario::TruthState;
use std::fmt::Write as _;

/// The header line (without newline).
pub const HEADER: &str = "frame,scan_start_s,scan_end_s,points,px_m,py_m,pz_m,qw,qx,qy,qz,yaw_deg,pitch_deg,roll_deg,vx_mps,vy_mps,vz_mps,wx_radps,wy_radps,wz_radps,range_m";

/// One CSV row (without newline).
pub fn row(
    frame: usize,
    scan_start: f64,
    scan_end: f64,
    points: usize,
    truth: &TruthState,
) -> String {
    let pose = &truth.t_sensor_target;
    let p = pose.translation;
    let q = UnitQuaternion::from_rotation_matrix(&pose.rotation);
    let [yaw, pitch, roll] = Euler321::from_rotation(&pose.rotation).to_degrees();
    let (v, w) = (truth.v_sensor_target, truth.w_target);
    let mut s = format!("{frame},{scan_start:.9},{scan_end:.9},{points}");
    for x in [
        p.x,
        p.y,
        p.z,
        q.w,
        q.i,
        q.j,
        q.k,
        yaw,
        pitch,
        roll,
        v.x,
        v.y,
        v.z,
        w.x,
        w.y,
        w.z,
        p.norm(),
    ] {
        // Writing to a String cannot fail.
        let _ = write!(s, ",{x:.9}");
    }
    s
}

/// Parses one row back into (frame, scan_end, position, quaternion); used by
/// tests and by tools that replay recorded frames.
pub fn parse_row(line: &str) -> Result<(usize, f64, [f64; 3], UnitQuaternion<f64>)> {
    let f: Vec<&str> = line.split(',').collect();
    if f.len() != HEADER.split(',').count() {
        anyhow::bail!(
            "truth row has {} columns, expected {}",
            f.len(),
            HEADER.split(',').count()
        );
    }
    let num = |i: usize| -> Result<f64> {
        f[i].parse::<f64>()
            .with_context(|| format!("column {i}: {:?}", f[i]))
    };
    let frame = f[0].parse::<usize>().context("frame column")?;
    let q = nalgebra::Quaternion::new(num(7)?, num(8)?, num(9)?, num(10)?);
    Ok((
        frame,
        num(2)?,
        [num(4)?, num(5)?, num(6)?],
        UnitQuaternion::from_quaternion(q),
    ))
}
