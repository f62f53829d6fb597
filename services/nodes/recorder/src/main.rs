//! `spacepose-recorder`: the run's clouds, poses, filter states,
//! acquisitions, health and truth into one MCAP file with Foxglove schemas
//! (README.md; logic in [`RecorderNode`]).

use spacepose_recorder_node::RecorderNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<RecorderNode>()
}
