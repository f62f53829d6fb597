//! Logging and shutdown.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// Logs to stderr with `tracing`; `RUST_LOG` is respected (default `info`).
/// Every line carries the service name as its target prefix.
pub fn init_logging(service: &str) {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    // A second call (tests) keeps the first subscriber.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
    tracing::debug!(service, "logging initialised");
}

/// A flag set on SIGINT or SIGTERM. The bus's waiters also report these
/// signals ([`spacepose_bus::WakeReason::TerminationRequested`]); loops stop
/// on either.
pub fn shutdown_flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if let Err(e) = signal_hook::flag::register(signal, Arc::clone(&flag)) {
            tracing::warn!("cannot register the handler of signal {signal}: {e}");
        }
    }
    flag
}
