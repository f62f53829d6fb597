//! Helpers of the end-to-end tests: finding the real binaries next to the
//! test executable, unique prefixes and ports, running `spacepose`, and
//! making sure every suite a test started is brought down.
//!
//! The service binaries are not built by `cargo test -p spacepose-e2e`; a
//! missing one fails the test with the command that builds it.
#![forbid(unsafe_code)]

pub mod layout;
pub mod net;

use spacepose_messages::ServiceKind;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};

/// Every binary a full suite needs: the CLI and one per service kind of
/// the topic graph.
pub fn suite_binaries() -> Vec<String> {
    std::iter::once("spacepose".to_string())
        .chain(ServiceKind::ALL.iter().map(|k| k.binary_name()))
        .collect()
}

/// `target/release/` (the directory of the binaries), from the test
/// executable's location (`target/release/deps/<test>`).
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test executable has a path");
    let deps = exe.parent().expect("the test executable is in a directory");
    if deps.file_name().is_some_and(|n| n == "deps") {
        deps.parent().expect("deps has a parent").to_path_buf()
    } else {
        deps.to_path_buf()
    }
}

/// Path of a binary of the workspace; panics, naming the build command, when
/// it has not been built.
pub fn binary(name: &str) -> PathBuf {
    let path = bin_dir().join(name);
    assert!(
        path.is_file(),
        "binary {name} is missing at {}: build every binary first with \
         `CARGO_TARGET_DIR=<same target dir> cargo build --release --workspace`",
        path.display(),
    );
    path
}

/// Checks that every suite binary exists (see [`binary`]).
pub fn require_suite() -> PathBuf {
    for b in suite_binaries() {
        binary(&b);
    }
    binary("spacepose")
}

/// Root of the repository (for `deploy/*.toml`).
pub fn repo_root() -> PathBuf {
    // The manifest directory cargo gives the test at run time, so a test
    // binary reused from another checkout's build reads this checkout.
    let dir = std::env::var("CARGO_MANIFEST_DIR")
        .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned());
    Path::new(&dir)
        .parent()
        .expect("tests/ is inside the repository")
        .to_path_buf()
}

/// A prefix no other test (or run) uses: `e2e-{tag}-{pid}-{n}`.
pub fn unique_prefix(tag: &str) -> String {
    static N: AtomicU32 = AtomicU32::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let mut p = format!("e2e-{tag}-{:x}{:x}-{n}", std::process::id(), nanos % 0xffff);
    p.truncate(32);
    p
}

/// A TCP port that was free a moment ago (bind to port 0, read, release).
pub fn free_port() -> u16 {
    let l = std::net::TcpListener::bind("127.0.0.1:0").expect("binding a loopback port");
    l.local_addr().expect("local address").port()
}

/// Runs `spacepose args…` to completion.
pub fn spacepose(args: &[&str]) -> Output {
    Command::new(binary("spacepose"))
        .args(args)
        .current_dir(repo_root())
        .stdin(Stdio::null())
        .output()
        .expect("running spacepose")
}

/// Both output streams of a finished command, for assertion messages.
pub fn text(o: &Output) -> String {
    format!(
        "status {}\n--- stdout\n{}\n--- stderr\n{}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Pids of live processes whose command line mentions `needle` (for "no
/// process remains" checks; zombies are not counted).
pub fn processes_mentioning(needle: &str) -> Vec<u32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    let me = std::process::id();
    entries
        .flatten()
        .filter_map(|e| e.file_name().to_str()?.parse::<u32>().ok())
        .filter(|pid| *pid != me)
        .filter(|pid| {
            let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
            let zombie = stat
                .rsplit_once(')')
                .is_some_and(|(_, r)| r.trim_start().starts_with('Z'));
            let cmd = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap_or_default();
            !zombie
                && String::from_utf8_lossy(&cmd)
                    .replace('\0', " ")
                    .contains(needle)
        })
        .collect()
}

/// Brings the deployment `prefix` down when dropped (whatever the test did).
#[derive(Debug)]
pub struct DownOnDrop(pub String);

impl Drop for DownOnDrop {
    fn drop(&mut self) {
        if Path::new(&state_file(&self.0)).exists() {
            let _ = spacepose(&["down", "--prefix", &self.0]);
        }
    }
}

/// The state file `spacepose up` writes for `prefix`.
pub fn state_file(prefix: &str) -> PathBuf {
    std::env::temp_dir()
        .join("spacepose")
        .join(prefix)
        .join("state.json")
}

/// The demo descriptor with lidar-sim's frames, rate and seed replaced.
pub fn demo_descriptor(dir: &Path, frames: u64, rate_hz: f64) -> PathBuf {
    let text = std::fs::read_to_string(repo_root().join("deploy/demo.toml"))
        .expect("deploy/demo.toml exists");
    let text = replace_key(&text, "frames", &frames.to_string());
    let text = replace_key(&text, "rate_hz", &format!("{rate_hz:.3}"));
    let path = dir.join("demo.toml");
    std::fs::write(&path, text).expect("writing the descriptor");
    path
}

/// Replaces the value of `key = …` lines (first occurrence in each line).
pub fn replace_key(text: &str, key: &str, value: &str) -> String {
    text.lines()
        .map(|l| {
            let t = l.trim_start();
            if t.starts_with(key) && t[key.len()..].trim_start().starts_with('=') {
                format!("{key} = {value}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// A scratch directory under the target directory (kept for inspection).
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = bin_dir().join("e2e").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("creating a scratch directory");
    dir
}

/// Version of the Python zenoh client the tests install.
pub const PYTHON_ZENOH: &str = "eclipse-zenoh==1.10.2";

/// A Python interpreter with `zenoh` importable (see [`python_with`]).
pub fn python_with_zenoh() -> Result<PathBuf, String> {
    python_with("zenoh", &[PYTHON_ZENOH], "import zenoh")
}

/// A Python interpreter of a venv under the target directory
/// (`target/release/e2e-venv-<name>`), created and filled with the pinned
/// `packages` on first use; `check` is Python code that must run in it
/// (an import). `Err` says why it is not available.
pub fn python_with(name: &str, packages: &[&str], check: &str) -> Result<PathBuf, String> {
    let venv = bin_dir().join(format!("e2e-venv-{name}"));
    let python = venv.join("bin").join("python");
    let usable = |py: &Path| {
        Command::new(py)
            .args(["-c", check])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if python.is_file() && usable(&python) {
        return Ok(python);
    }
    let run = |cmd: &mut Command, what: &str| -> Result<(), String> {
        let o = cmd.output().map_err(|e| format!("{what}: {e}"))?;
        if o.status.success() {
            Ok(())
        } else {
            let err = String::from_utf8_lossy(&o.stderr);
            let tail: Vec<&str> = err.lines().rev().take(3).collect();
            Err(format!(
                "{what} failed ({}): {}",
                o.status,
                tail.join(" / ")
            ))
        }
    };
    run(
        Command::new("python3").args(["-m", "venv"]).arg(&venv),
        "python3 -m venv",
    )?;
    let mut pip = Command::new(venv.join("bin").join("pip"));
    pip.args(["install", "--quiet", "--disable-pip-version-check"])
        .args(packages);
    run(&mut pip, &format!("pip install {}", packages.join(" ")))?;
    if usable(&python) {
        Ok(python)
    } else {
        Err(format!(
            "`{check}` fails after installing {}",
            packages.join(" ")
        ))
    }
}
