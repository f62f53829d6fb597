//! `spacepose up`: validate a descriptor, start its services, wait for their
//! heartbeats, leave them running.

use super::binaries::BinarySearch;
use super::descriptor::Descriptor;
use super::health::HealthWatch;
use super::launch::{RunningSuite, start};
use super::plan::{ConfigCheck, Plan, plan};
use anyhow::{Context, Result};
use spacepose_bus::Bus;
use std::io::Write;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::time::Duration;

/// Command-line overrides of a descriptor.
#[derive(Debug, Clone, Default)]
pub struct Overrides {
    /// Deployment prefix.
    pub prefix: Option<String>,
    /// zenoh endpoints to listen on (replace the descriptor's).
    pub listen: Option<Vec<String>>,
    /// zenoh endpoints to connect to (replace the descriptor's).
    pub connect: Option<Vec<String>>,
    /// The host whose part of a partitioned descriptor to start.
    pub host: Option<String>,
    /// Record the run into this MCAP file (absolute): a recorder instance
    /// is added ([`super::record::add_recorder`]).
    pub record: Option<std::path::PathBuf>,
    /// Serve the run live to Foxglove on this (loopback) address: a
    /// recorder's live view ([`super::record::add_live_view`]).
    pub view: Option<std::net::SocketAddr>,
}

impl Overrides {
    /// Applies the overrides to `d`.
    pub fn apply(&self, d: &mut Descriptor) {
        if let Some(p) = &self.prefix {
            d.prefix.clone_from(p);
        }
        if let Some(l) = &self.listen {
            d.zenoh.listen.clone_from(l);
        }
        if let Some(c) = &self.connect {
            d.zenoh.connect.clone_from(c);
        }
        if let Some(file) = &self.record {
            super::record::add_recorder(d, file);
        }
        if let Some(addr) = self.view {
            super::record::add_live_view(d, addr);
        }
    }
}

/// Loads, overrides and validates a descriptor file.
pub fn load_plan(path: &Path, overrides: &Overrides) -> Result<(Descriptor, Plan)> {
    let mut d = Descriptor::load(path)?;
    if let Some(host) = &overrides.host {
        let base = path.parent().unwrap_or(Path::new("."));
        d = super::partition::host_part(&d, host, base)
            .with_context(|| format!("host {host:?} of {} was not started", path.display()))?;
    }
    overrides.apply(&mut d);
    let p = plan_descriptor(&d, path)?;
    Ok((d, p))
}

/// Validates an (already overridden) descriptor read from `path`.
pub fn plan_descriptor(d: &Descriptor, path: &Path) -> Result<Plan> {
    let base = path.parent().unwrap_or(Path::new("."));
    let search = BinarySearch::from_env(base);
    plan(d, &search, ConfigCheck::Run)
        .with_context(|| format!("{} was not started", path.display()))
}

/// Opens this process's bus node for a plan and starts the suite.
pub fn bring_up(
    plan: &Plan,
    role: &str,
    out: &mut dyn Write,
) -> Result<(Bus, HealthWatch, RunningSuite)> {
    let bus = Bus::open(
        &plan.names,
        // iceoryx2 node names hold at most 24 bytes: `sp-`, a role of at
        // most 10 bytes, and a pid of up to 7 digits (Linux pid_max 4194304).
        &format!("sp-{role}-{}", std::process::id()),
    )
    .context("opening the iceoryx2 node")?;
    let mut watch = HealthWatch::new(&bus, &plan.names)?;
    let suite = start(plan, &mut watch, out)?;
    Ok((bus, watch, suite))
}

/// Output of the supervisor: its log file, and stdout until the suite is
/// ready (`up` reads it through a pipe, then exits).
struct SupervisorOut {
    stdout: Option<std::io::Stdout>,
    log: std::fs::File,
}

impl Write for SupervisorOut {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if let Some(o) = &mut self.stdout {
            let _ = o.write_all(buf);
        }
        self.log.write_all(buf)?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if let Some(o) = &mut self.stdout {
            let _ = o.flush();
        }
        self.log.flush()
    }
}

/// The line the supervisor prints once every instance is healthy.
const READY: &str = "supervisor ready";

fn override_args(overrides: &Overrides) -> Vec<String> {
    let mut args = Vec::new();
    if let Some(p) = &overrides.prefix {
        args.extend(["--prefix".to_string(), p.clone()]);
    }
    for l in overrides.listen.iter().flatten() {
        args.extend(["--listen".to_string(), l.clone()]);
    }
    for c in overrides.connect.iter().flatten() {
        args.extend(["--connect".to_string(), c.clone()]);
    }
    if let Some(h) = &overrides.host {
        args.extend(["--host".to_string(), h.clone()]);
    }
    if let Some(r) = &overrides.record {
        args.extend(["--record".to_string(), r.display().to_string()]);
    }
    if let Some(v) = &overrides.view {
        args.extend(["--view".to_string(), v.to_string()]);
    }
    args
}

/// `spacepose up <descriptor>`: validates, then starts the supervisor
/// process (`spacepose supervise`, its own process group, log in the run
/// directory), relays its progress and returns once the suite is healthy.
pub fn run(path: &Path, overrides: &Overrides, out: &mut dyn Write) -> Result<()> {
    use std::io::BufRead;
    let (_, plan) = load_plan(path, overrides)?;
    let prefix = plan.names.prefix().to_string();
    super::launch::check_not_running(&prefix)?;
    let dir = super::state::run_dir(&prefix);
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let log_path = dir.join("supervisor.log");
    let log = std::fs::File::create(&log_path)
        .with_context(|| format!("cannot create {}", log_path.display()))?;
    let exe = std::env::current_exe().context("locating the spacepose executable")?;
    let mut overrides = overrides.clone();
    overrides.prefix = Some(prefix.clone());
    let mut child = std::process::Command::new(exe)
        .arg("supervise")
        .arg(path)
        .args(override_args(&overrides))
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(log)
        .process_group(0)
        .spawn()
        .context("starting the supervisor")?;
    let stdout = child.stdout.take().context("supervisor stdout")?;
    for line in std::io::BufReader::new(stdout).lines() {
        let line = line?;
        if line == READY {
            writeln!(
                out,
                "deployment {prefix:?} is up, supervised by pid {}; logs in {}; \
                 stop it with `spacepose down --prefix {prefix}`",
                child.id(),
                dir.display()
            )?;
            return Ok(());
        }
        writeln!(out, "{line}")?;
    }
    let status = child.wait()?;
    anyhow::bail!(
        "the supervisor exited ({status}) before the suite was up; last lines of {}:\n{}",
        log_path.display(),
        super::process::log_tail(&log_path, 20)
    )
}

/// Path of the swap request / result files of a deployment.
fn swap_files(prefix: &str) -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = super::state::run_dir(prefix);
    (dir.join("swap-request.json"), dir.join("swap-result.json"))
}

/// `spacepose supervise`: brings the suite up and supervises it until
/// SIGTERM/SIGINT (`spacepose down`), then stops it.
pub fn supervise(path: &Path, overrides: &Overrides) -> Result<()> {
    use std::sync::atomic::Ordering;
    let (_, plan) = load_plan(path, overrides)?;
    let prefix = plan.names.prefix().to_string();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        signal_hook::flag::register(sig, std::sync::Arc::clone(&stop))?;
    }
    let log_path = super::state::run_dir(&prefix).join("supervisor.log");
    let log = std::fs::File::options()
        .create(true)
        .append(true)
        .open(&log_path)?;
    let mut out = SupervisorOut {
        stdout: Some(std::io::stdout()),
        log,
    };
    let (bus, watch, suite) = bring_up(&plan, "sup", &mut out)?;
    let mut sup = super::supervisor::Supervisor::new(plan, bus, watch, suite)?;
    writeln!(out, "{READY}")?;
    out.flush()?;
    out.stdout = None;
    let (request, result) = swap_files(&prefix);
    let mut reported = 0;
    while !stop.load(Ordering::Relaxed) {
        sup.step(&mut out)?;
        if request.exists() {
            let taken = request.with_extension("taken");
            std::fs::rename(&request, &taken)?;
            let req = std::fs::read_to_string(&taken)
                .map_err(anyhow::Error::from)
                .and_then(|t| Ok(serde_json::from_str::<super::swap::SwapRequest>(&t)?));
            if let Err(e) = req.and_then(|r| sup.request_swap(r, &mut out)) {
                write_json(&result, &serde_json::json!({ "error": format!("{e:#}") }))?;
            }
        }
        if sup.swaps.len() > reported {
            reported = sup.swaps.len();
            write_json(&result, &sup.swaps[reported - 1])?;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    writeln!(out, "supervisor: stopping the suite")?;
    sup.stop(&mut out)
}

fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, serde_json::to_string_pretty(value)?)?;
    std::fs::rename(&tmp, path)?;
    Ok(())
}

/// `spacepose swap`: hands the request to the deployment's supervisor and
/// waits for its report.
pub fn request_swap(
    prefix: Option<&str>,
    req: &super::swap::SwapRequest,
    timeout: Duration,
    out: &mut dyn Write,
) -> Result<()> {
    let state = super::state::RunState::select(prefix)?;
    let alive = state.supervisor_pid.is_some_and(|pid| {
        std::env::current_exe().is_ok_and(|exe| super::process::is_alive(pid, &exe))
    });
    if !alive {
        anyhow::bail!(
            "deployment {:?} has no running supervisor (started by an older `spacepose up`?)",
            state.prefix
        );
    }
    let (request, result) = swap_files(&state.prefix);
    let _ = std::fs::remove_file(&result);
    write_json(&request, req)?;
    writeln!(out, "swap requested on {:?}", state.prefix)?;
    let start = std::time::Instant::now();
    while start.elapsed() < timeout {
        if let Ok(text) = std::fs::read_to_string(&result) {
            let v: serde_json::Value = serde_json::from_str(&text)?;
            if let Some(e) = v.get("error").and_then(serde_json::Value::as_str) {
                anyhow::bail!("swap failed: {e}");
            }
            let r: super::swap::SwapReport = serde_json::from_value(v)?;
            writeln!(out, "{}", r.line())?;
            return Ok(());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    anyhow::bail!("no swap result within {} s", timeout.as_secs_f64())
}
