//! Helpers shared by the integration tests.

#![allow(dead_code, clippy::unwrap_used)] // test helpers may unwrap

use spacepose_messages::Names;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

/// A deployment of its own for each test, so tests run in parallel.
pub fn unique_names(tag: &str) -> Names {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    let prefix = format!(
        "t{}-{}-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed),
        nanos % 100_000,
        tag
    );
    Names::new(&prefix[..prefix.len().min(32)]).unwrap()
}

/// A TCP port that was free a moment ago on loopback.
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}
