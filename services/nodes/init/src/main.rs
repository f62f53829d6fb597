//! `spacepose-init`: acquires the pose at start and whenever the tracker
//! reports `lost`, one `AcquisitionResult` per attempt (README.md; logic in
//! [`InitNode`]).

use spacepose_init_node::InitNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<InitNode>()
}
