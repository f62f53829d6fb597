//! Starting a planned deployment: consumers first, then the sources, each
//! stage only once every instance of the previous one has sent a heartbeat.
//! On any failure, whatever was started is stopped again.

use super::health::HealthWatch;
use super::plan::{Plan, PlannedInstance};
use super::process::{is_alive, log_tail, spawn_logged, terminate};
use super::state::{InstanceState, RunState, run_dir, unix_now_s};
use anyhow::{Context, Result, bail};
use std::io::Write;
use std::path::PathBuf;
use std::process::Child;
use std::time::{Duration, Instant};

pub use super::process::STOP_GRACE;

/// A deployment started by this process.
#[derive(Debug)]
pub struct RunningSuite {
    /// What was started (also in `state.json`).
    pub state: RunState,
    children: Vec<Child>,
}

/// Command-line arguments of one instance.
fn instance_args(plan: &Plan, instance: &PlannedInstance, config: &std::path::Path) -> Vec<String> {
    vec![
        "--config".into(),
        config.display().to_string(),
        "--prefix".into(),
        plan.names.prefix().to_string(),
        "--instance".into(),
        instance.name.clone(),
        "--heartbeat-ms".into(),
        plan.heartbeat_ms.to_string(),
    ]
}

/// Refuses to start over a live deployment of the same prefix; removes a
/// stale state file.
pub fn check_not_running(prefix: &str) -> Result<()> {
    let Ok(old) = RunState::load(prefix) else {
        return Ok(());
    };
    let alive: Vec<&str> = old
        .instances
        .iter()
        .filter(|i| is_alive(i.pid, &i.binary))
        .map(|i| i.name.as_str())
        .collect();
    if !alive.is_empty() {
        bail!(
            "deployment {prefix:?} is already running ({}): stop it with `spacepose down --prefix {prefix}`",
            alive.join(", ")
        );
    }
    let _ = std::fs::remove_file(RunState::path(prefix));
    Ok(())
}

/// Starts every instance of `plan` and waits for their heartbeats on `watch`.
/// Progress goes to `out`.
pub fn start(plan: &Plan, watch: &mut HealthWatch, out: &mut dyn Write) -> Result<RunningSuite> {
    let prefix = plan.names.prefix().to_string();
    check_not_running(&prefix)?;
    let dir = run_dir(&prefix);
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    // NDT maps cached by an earlier run of this prefix may be of another
    // target; filter snapshots and sensor checkpoints are of another run
    // (restarts keep all three).
    for e in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
        if e.path()
            .extension()
            .is_some_and(|x| x == "ndtmap" || x == "filterstate" || x == "sensorstate")
        {
            let _ = std::fs::remove_file(e.path());
        }
    }
    let mut suite = RunningSuite {
        state: RunState {
            prefix: prefix.clone(),
            heartbeat_ms: plan.heartbeat_ms,
            started_unix_s: unix_now_s(),
            started_by_pid: std::process::id(),
            supervisor_pid: None,
            primary: super::plan::configured_primary(plan),
            instances: Vec::new(),
        },
        children: Vec::new(),
    };
    let (consumers, sources) = plan.start_order();
    for stage in [consumers, sources] {
        if let Err(e) = start_stage(plan, &stage, &mut suite, watch, out) {
            let _ = suite.stop(out);
            return Err(e);
        }
    }
    suite.state.save()?;
    Ok(suite)
}

fn start_stage(
    plan: &Plan,
    stage: &[&PlannedInstance],
    suite: &mut RunningSuite,
    watch: &mut HealthWatch,
    out: &mut dyn Write,
) -> Result<()> {
    let first = suite.children.len();
    for instance in stage {
        let log = run_dir(plan.names.prefix()).join(format!("{}.log", instance.name));
        let _ = std::fs::remove_file(&log);
        let pid = suite.spawn_instance(plan, instance)?;
        writeln!(
            out,
            "started {:<12} {:<10} pid {}",
            instance.name, instance.kind, pid
        )?;
        // Keep a partial state file, so `down` can stop a half-started suite.
        suite.state.save()?;
    }
    wait_healthy(suite, first, plan.health_timeout, watch)?;
    for i in &suite.state.instances[first..] {
        writeln!(out, "healthy {:<12} {:<10}", i.name, i.kind)?;
    }
    Ok(())
}

/// Waits until every instance from index `first` has sent a heartbeat from
/// its own pid; fails as soon as one exits.
fn wait_healthy(
    suite: &mut RunningSuite,
    first: usize,
    timeout: Duration,
    watch: &mut HealthWatch,
) -> Result<()> {
    let deadline = Instant::now() + timeout;
    loop {
        watch.poll(Duration::from_millis(100))?;
        let mut waiting = Vec::new();
        for (i, child) in suite.children.iter_mut().enumerate().skip(first) {
            let inst = &suite.state.instances[i];
            if let Ok(Some(status)) = child.try_wait() {
                bail!(
                    "service {:?} ({}) exited during start-up ({status}); last lines of {}:\n{}",
                    inst.name,
                    inst.kind,
                    inst.log.display(),
                    log_tail(&inst.log, 15)
                );
            }
            if watch.get(&inst.name).is_none_or(|h| h.pid != inst.pid) {
                waiting.push(i);
            }
        }
        if waiting.is_empty() {
            return Ok(());
        }
        if Instant::now() >= deadline {
            let mut msg = String::new();
            for i in waiting {
                let inst = &suite.state.instances[i];
                msg.push_str(&format!(
                    "\nservice {:?} ({}) sent no heartbeat within {:.0} s; last lines of {}:\n{}",
                    inst.name,
                    inst.kind,
                    timeout.as_secs_f64(),
                    inst.log.display(),
                    log_tail(&inst.log, 15)
                ));
            }
            bail!("the suite did not become healthy:{msg}");
        }
    }
}

impl RunningSuite {
    /// Starts `instance` (config file written, log appended). When an
    /// instance of that name exists (a restart), its process is replaced.
    /// Returns the pid.
    pub fn spawn_instance(&mut self, plan: &Plan, instance: &PlannedInstance) -> Result<u32> {
        let dir = run_dir(plan.names.prefix());
        let config = dir.join(format!("{}.toml", instance.name));
        std::fs::write(&config, toml::to_string(&instance.config)?)
            .with_context(|| format!("cannot write {}", config.display()))?;
        let log = dir.join(format!("{}.log", instance.name));
        let child = spawn_logged(
            &instance.binary,
            &instance_args(plan, instance, &config),
            &log,
        )
        .with_context(|| format!("service {:?}", instance.name))?;
        let pid = child.id();
        let state = InstanceState {
            name: instance.name.clone(),
            kind: instance.kind,
            pid,
            binary: instance.binary.clone(),
            log,
            role: String::new(),
            status: "starting".into(),
            restarts: 0,
            last_frame: None,
        };
        match self.index(&instance.name) {
            Some(i) => {
                let old = &mut self.state.instances[i];
                let restarts = old.restarts;
                let role = std::mem::take(&mut old.role);
                *old = InstanceState {
                    restarts,
                    role,
                    ..state
                };
                self.children[i] = child;
            }
            None => {
                self.state.instances.push(state);
                self.children.push(child);
            }
        }
        Ok(pid)
    }

    /// Index of an instance.
    pub fn index(&self, instance: &str) -> Option<usize> {
        self.state.instances.iter().position(|i| i.name == instance)
    }

    /// The exit status of an instance whose process has exited (reaped).
    pub fn try_exit(&mut self, instance: &str) -> Option<std::process::ExitStatus> {
        let i = self.index(instance)?;
        self.children[i].try_wait().ok().flatten()
    }

    /// Sends `signal` to an instance's process group.
    pub fn signal(&self, instance: &str, signal: rustix::process::Signal) {
        if let Some(pid) = self.pid(instance) {
            super::process::signal_group(pid, signal);
        }
    }

    /// Forgets an instance (after it exited, e.g. swapped out).
    pub fn remove(&mut self, instance: &str) {
        if let Some(i) = self.index(instance) {
            let mut child = self.children.remove(i);
            let _ = child.try_wait();
            self.state.instances.remove(i);
        }
    }

    /// Process id of an instance.
    pub fn pid(&self, instance: &str) -> Option<u32> {
        self.state
            .instances
            .iter()
            .find(|i| i.name == instance)
            .map(|i| i.pid)
    }

    /// Instances whose process has exited (name, exit status).
    pub fn exited(&mut self) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for (child, inst) in self.children.iter_mut().zip(&self.state.instances) {
            if let Ok(Some(status)) = child.try_wait() {
                out.push((inst.name.clone(), status.to_string()));
            }
        }
        out
    }

    /// The log file of an instance.
    pub fn log(&self, instance: &str) -> Option<PathBuf> {
        self.state
            .instances
            .iter()
            .find(|i| i.name == instance)
            .map(|i| i.log.clone())
    }

    /// A suite of no instance yet, for unit tests that spawn into it.
    #[cfg(test)]
    pub(crate) fn empty(state: RunState) -> Self {
        Self {
            state,
            children: Vec::new(),
        }
    }

    /// Leaves the processes running (after `up`): they are reparented.
    pub fn detach(self) -> RunState {
        self.state
    }

    /// Stops every instance (SIGTERM, then SIGKILL after [`STOP_GRACE`]) and
    /// removes the state file and the stale bus resources.
    pub fn stop(mut self, out: &mut dyn Write) -> Result<()> {
        let procs: Vec<(&str, u32, &std::path::Path)> = self
            .state
            .instances
            .iter()
            .map(|i| (i.name.as_str(), i.pid, i.binary.as_path()))
            .collect();
        let children = &mut self.children;
        let killed = terminate(&procs, STOP_GRACE, || {
            for c in children.iter_mut() {
                let _ = c.try_wait();
            }
        });
        for c in self.children.iter_mut() {
            let _ = c.wait();
        }
        if !killed.is_empty() {
            writeln!(
                out,
                "killed after {} s: {}",
                STOP_GRACE.as_secs(),
                killed.join(", ")
            )?;
        }
        super::down::cleanup(&self.state.prefix, out)
    }
}
