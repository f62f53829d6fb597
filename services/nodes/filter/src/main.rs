//! `spacepose-filter`: the authority on the relative motion; fuses one
//! tracker estimate per frame and publishes the `FilterState` (README.md;
//! logic in [`FilterNode`]).

use spacepose_filter_node::FilterNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<FilterNode>()
}
