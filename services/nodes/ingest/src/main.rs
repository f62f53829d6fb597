//! `spacepose-ingest`: validates each raw frame and crops it to the
//! target's region of interest (README.md; logic in [`IngestNode`]).

use spacepose_ingest_node::IngestNode;
use std::process::ExitCode;

fn main() -> ExitCode {
    spacepose_runtime::main::<IngestNode>()
}
