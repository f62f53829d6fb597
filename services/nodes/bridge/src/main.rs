//! `spacepose-bridge`: the host bridge of a partitioned suite. The runtime
//! opens the host's link (listening hosts check the peers' accounts and
//! enforce the link ACL; connecting hosts present theirs), starts the
//! routes on the link keys and optionally waits for the consuming hosts;
//! [`BridgeNode`] reports the counters in the heartbeat and in
//! `stats_file` (README.md).

use spacepose_bridge_node::BridgeNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<BridgeNode>()
}
