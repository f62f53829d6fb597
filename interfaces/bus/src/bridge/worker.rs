//! The worker threads of a bridge: the body type, how often they look at
//! the stop flag, and spawning one.

use crate::error::BusError;
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

/// How long the workers block before looking at the stop flag.
pub(crate) const STOP_POLL: Duration = Duration::from_millis(100);

/// A worker body: set up, report readiness once, then run until stopped.
pub(crate) type Run = Box<dyn FnOnce(&dyn Fn(Result<(), BusError>)) + Send>;

pub(crate) fn spawn(
    name: &str,
    ready: mpsc::Sender<Result<(), BusError>>,
    run: Run,
) -> Result<JoinHandle<()>, BusError> {
    std::thread::Builder::new()
        .name(name.to_string())
        .spawn(move || {
            let report = move |r: Result<(), BusError>| {
                // The starter may have given up already; nothing else to do then.
                let _ = ready.send(r);
            };
            run(&report)
        })
        .map_err(|e| BusError::BridgeWorker(format!("spawning {name}: {e}")))
}
