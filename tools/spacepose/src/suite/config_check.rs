//! Checking a service configuration with the service's own binary
//! (`binary --config FILE --check`: parse, validate, exit; the bus is never
//! touched), so the descriptor is checked by the very types that will read it.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longest a `--check` may take.
const CHECK_TIMEOUT: Duration = Duration::from_secs(20);

/// Writes `config` to a temporary file and runs `binary --config FILE --check`.
/// `Err` carries the binary's own message.
pub fn check_config(binary: &Path, config: &toml::Table) -> Result<(), String> {
    let text =
        toml::to_string(config).map_err(|e| format!("cannot write the config as TOML: {e}"))?;
    let dir = std::env::temp_dir().join("spacepose").join("check");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let file = dir.join(format!(
        "{}-{}.toml",
        binary
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("service"),
        std::process::id()
    ));
    std::fs::write(&file, text).map_err(|e| format!("cannot write {}: {e}", file.display()))?;
    let result = run_check(binary, &file);
    let _ = std::fs::remove_file(&file);
    result
}

fn run_check(binary: &Path, file: &Path) -> Result<(), String> {
    let mut child = Command::new(binary)
        .arg("--config")
        .arg(file)
        .arg("--check")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run {}: {e}", binary.display()))?;
    let started = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if started.elapsed() > CHECK_TIMEOUT => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!(
                    "{} --check did not finish within {} s",
                    binary.display(),
                    CHECK_TIMEOUT.as_secs()
                ));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(e) => return Err(format!("waiting for {}: {e}", binary.display())),
        }
    };
    let mut stderr = String::new();
    if let Some(mut s) = child.stderr.take() {
        let _ = s.read_to_string(&mut stderr);
    }
    if status.success() {
        return Ok(());
    }
    let message = stderr
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(strip_ansi)
        .map(|l| strip_log_prefix(&l).to_string())
        .collect::<Vec<_>>()
        .join(" / ");
    Err(if message.is_empty() {
        format!("{} --check failed ({status})", binary.display())
    } else {
        message
    })
}

/// The message of a `tracing` line (`<time>  ERROR <target>: <message>`).
fn strip_log_prefix(line: &str) -> &str {
    match line.split_once(" ERROR ") {
        Some((_, rest)) => rest.split_once(": ").map_or(rest, |(_, m)| m),
        None => line,
    }
}

/// Removes ANSI colour sequences from a log line.
pub fn strip_ansi(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '\u{1b}' {
            for d in chars.by_ref() {
                if d.is_ascii_alphabetic() {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn script(dir: &Path, body: &str) -> std::path::PathBuf {
        use std::os::unix::fs::PermissionsExt;
        let p = dir.join("svc");
        std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
        p
    }

    #[test]
    fn exit_status_and_message_of_the_binary_decide() {
        let dir = tempfile::tempdir().unwrap();
        let ok = script(
            dir.path(),
            "grep -q 'rate_hz = 5' \"$2\" && [ \"$3\" = --check ]",
        );
        let mut c = toml::Table::new();
        c.insert("rate_hz".into(), toml::Value::Float(5.0));
        check_config(&ok, &c).unwrap();
        let bad = script(
            dir.path(),
            "echo 'invalid config: unknown field `rate`' >&2; exit 1",
        );
        let e = check_config(&bad, &c).unwrap_err();
        assert!(e.contains("unknown field `rate`"), "{e}");
    }

    #[test]
    fn ansi_codes_are_stripped() {
        assert_eq!(strip_ansi("\u{1b}[31mERROR\u{1b}[0m x"), "ERROR x");
        assert_eq!(
            strip_log_prefix("2026-01-01T00:00:00Z ERROR spacepose_ingest: invalid config: x"),
            "invalid config: x"
        );
    }
}
