//! `spacepose-lidar-sim`: publishes simulated raw frames, their truth and
//! optionally the truth acquisition of the first frame (README.md; logic
//! in [`LidarSimNode`]).

use spacepose_lidar_sim_node::LidarSimNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<LidarSimNode>()
}
