//! Service processes: spawning in their own process group with logs to a
//! file, liveness, and termination (SIGTERM, then SIGKILL).

use anyhow::{Context, Result};
use rustix::process::{Pid, Signal};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Spawns `binary args…` in a new process group, stdin closed, stdout and
/// stderr appended to `log`.
pub fn spawn_logged(binary: &Path, args: &[String], log: &Path) -> Result<Child> {
    let out = File::options()
        .create(true)
        .append(true)
        .open(log)
        .with_context(|| format!("cannot open log file {}", log.display()))?;
    let err = out.try_clone()?;
    Command::new(binary)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::from(out))
        .stderr(Stdio::from(err))
        .process_group(0)
        .spawn()
        .with_context(|| format!("cannot start {}", binary.display()))
}

/// True when `pid` runs (not a zombie) and its command is `binary`'s file
/// name (guards against pid reuse).
pub fn is_alive(pid: u32, binary: &Path) -> bool {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return false;
    };
    // "pid (comm) S ...": the state follows the last ')'.
    let state = stat
        .rsplit_once(')')
        .and_then(|(_, rest)| rest.split_whitespace().next());
    if matches!(state, Some("Z" | "X") | None) {
        return false;
    }
    let Ok(cmdline) = std::fs::read(format!("/proc/{pid}/cmdline")) else {
        return false;
    };
    if cmdline.is_empty() {
        // Briefly empty while the process execs: alive.
        return true;
    }
    let argv0 = cmdline.split(|b| *b == 0).next().unwrap_or_default();
    let argv0 = Path::new(std::str::from_utf8(argv0).unwrap_or_default());
    argv0.file_name() == binary.file_name()
}

/// Sends `signal` to the process group led by `pid` (each service leads
/// its own), or to the process alone when that fails.
pub fn signal_group(pid: u32, signal: Signal) {
    let Some(pid) = i32::try_from(pid).ok().and_then(Pid::from_raw) else {
        return;
    };
    // Each service leads its own group (pgid = pid): signal the whole group.
    if rustix::process::kill_process_group(pid, signal).is_err() {
        let _ = rustix::process::kill_process(pid, signal);
    }
}

/// How long a service gets to stop after SIGTERM before SIGKILL.
pub const STOP_GRACE: Duration = Duration::from_secs(5);

/// Sends SIGTERM to each live process of `procs` (pid, binary), waits up
/// to `grace` for them to exit (reaping through `reap`), then SIGKILLs the
/// stragglers. Returns the names of the processes that had to be killed.
pub fn terminate<'a>(
    procs: &[(&'a str, u32, &Path)],
    grace: Duration,
    mut reap: impl FnMut(),
) -> Vec<&'a str> {
    for (_, pid, binary) in procs {
        if is_alive(*pid, binary) {
            signal_group(*pid, Signal::TERM);
        }
    }
    let deadline = Instant::now() + grace;
    loop {
        reap();
        let alive = procs.iter().any(|(_, pid, b)| is_alive(*pid, b));
        if !alive || Instant::now() >= deadline {
            break;
        }
        std::thread::sleep(Duration::from_millis(25));
    }
    let mut killed = Vec::new();
    for (name, pid, binary) in procs {
        if is_alive(*pid, binary) {
            signal_group(*pid, Signal::KILL);
            killed.push(*name);
        }
    }
    if !killed.is_empty() {
        let deadline = Instant::now() + Duration::from_secs(2);
        while Instant::now() < deadline && procs.iter().any(|(_, pid, b)| is_alive(*pid, b)) {
            reap();
            std::thread::sleep(Duration::from_millis(10));
        }
    }
    killed
}

/// The last `lines` lines of a log file (empty when unreadable).
pub fn log_tail(path: &Path, lines: usize) -> String {
    let Ok(mut f) = File::open(path) else {
        return String::new();
    };
    let len = f.metadata().map_or(0, |m| m.len());
    let start = len.saturating_sub(16 * 1024);
    let mut text = String::new();
    if f.seek(SeekFrom::Start(start)).is_err() {
        return text;
    }
    let mut bytes = Vec::new();
    let _ = f.read_to_end(&mut bytes);
    text = String::from_utf8_lossy(&bytes).into_owned();
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..]
        .iter()
        .map(|l| super::config_check::strip_ansi(l))
        .collect::<Vec<_>>()
        .join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spawned_processes_are_alive_until_terminated() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("sleep.log");
        let sleep = Path::new("/bin/sleep");
        let mut child = spawn_logged(sleep, &["30".to_string()], &log).unwrap();
        let pid = child.id();
        assert!(is_alive(pid, sleep));
        // Let the exec finish (its command line is briefly empty).
        std::thread::sleep(Duration::from_millis(100));
        assert!(is_alive(pid, sleep));
        assert!(!is_alive(pid, Path::new("/bin/other")));
        let killed = terminate(&[("s", pid, sleep)], Duration::from_secs(5), || {
            let _ = child.try_wait();
        });
        assert!(killed.is_empty());
        assert!(!is_alive(pid, sleep));
    }

    #[test]
    fn stragglers_are_killed_and_logs_are_tailed() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("trap.log");
        let sh = Path::new("/bin/sh");
        let script = "trap '' TERM; echo one; echo two; while true; do sleep 0.05; done";
        let mut child = spawn_logged(sh, &["-c".into(), script.into()], &log).unwrap();
        std::thread::sleep(Duration::from_millis(300));
        let killed = terminate(&[("t", child.id(), sh)], Duration::from_millis(300), || {
            let _ = child.try_wait();
        });
        assert_eq!(killed, vec!["t"]);
        assert_eq!(log_tail(&log, 1), "two");
        assert_eq!(log_tail(&log, 5), "one\ntwo");
    }
}
