//! `spacepose-telemetry`: pose, filter state, health, truth and errors as
//! JSON on the ground link, the queryable `latest`, and the ground's
//! commands into the suite (README.md; logic in [`TelemetryNode`]).

use spacepose_telemetry_node::TelemetryNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<TelemetryNode>()
}
