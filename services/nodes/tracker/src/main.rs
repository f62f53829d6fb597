//! `spacepose-tracker`: follows the target frame after frame, one pose
//! estimate per cloud (README.md; logic in [`TrackerNode`]).

use spacepose_tracker_node::TrackerNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<TrackerNode>()
}
