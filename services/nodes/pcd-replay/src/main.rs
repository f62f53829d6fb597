//! `spacepose-pcd-replay`: publishes a directory of recorded frames as raw
//! clouds (README.md; logic in [`PcdReplayNode`]).

use spacepose_pcd_replay_node::PcdReplayNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<PcdReplayNode>()
}
