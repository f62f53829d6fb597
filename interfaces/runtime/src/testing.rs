//! Helpers for process-level tests of service binaries: a guard that kills
//! the child process when a test fails, a polling wait with a deadline, and
//! a deployment prefix unique to the calling test, so bus tests can run in
//! parallel without meeting.

use std::process::{Child, Command, ExitStatus};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Owns a started service process and kills it when dropped (also when a
/// test panics before stopping it).
pub struct ChildGuard(pub Child);

impl Drop for ChildGuard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl ChildGuard {
    /// Sends SIGTERM (the way a supervisor stops a service) and waits up to
    /// `timeout` for the exit; panics if `kill` fails or the process is
    /// still running then.
    pub fn terminate(&mut self, timeout: Duration) -> ExitStatus {
        let pid = self.0.id().to_string();
        let sent = Command::new("kill").args(["-TERM", &pid]).status();
        assert!(
            sent.as_ref().is_ok_and(|s| s.success()),
            "kill -TERM {pid}: {sent:?}"
        );
        wait_for("the exit after SIGTERM", timeout, || {
            self.0.try_wait().ok().flatten()
        })
    }
}

/// Polls `f` every 2 ms until it returns a value; panics naming `what`
/// after `timeout`.
pub fn wait_for<T>(what: &str, timeout: Duration, mut f: impl FnMut() -> Option<T>) -> T {
    let start = Instant::now();
    while start.elapsed() < timeout {
        if let Some(v) = f() {
            return v;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    panic!("timed out after {timeout:?} waiting for {what}");
}

/// A deployment prefix made of `tag`, the process id and the clock's
/// nanoseconds: valid for `Names::new` (`[a-z0-9_-]`, at most 32 characters
/// for a tag of up to 8) and distinct between tests and test runs.
pub fn unique_prefix(tag: &str) -> String {
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    format!("{tag}{}x{nanos}", std::process::id())
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_messages::Names;

    #[test]
    fn prefixes_are_valid_names_and_distinct() {
        let a = unique_prefix("ingest");
        std::thread::sleep(Duration::from_millis(1));
        let b = unique_prefix("ingest");
        assert_ne!(a, b);
        assert!(Names::new(&a).is_ok(), "{a}");
    }

    #[test]
    fn wait_for_returns_the_first_value() {
        let mut n = 0;
        assert_eq!(
            wait_for("three calls", Duration::from_secs(1), || {
                n += 1;
                (n == 3).then_some(n)
            }),
            3
        );
    }

    #[test]
    fn terminate_stops_the_process() {
        let child = Command::new("sleep").arg("30").spawn().unwrap();
        let mut guard = ChildGuard(child);
        let status = guard.terminate(Duration::from_secs(5));
        // `sleep` does not handle SIGTERM: it dies of it.
        assert!(!status.success());
    }

    #[test]
    #[should_panic(expected = "waiting for nothing")]
    fn wait_for_panics_after_its_timeout() {
        wait_for::<()>("nothing", Duration::from_millis(10), || None);
    }
}
