//! `spacepose status`: a table of the instances of running deployments.

use super::health::HealthWatch;
use super::process::is_alive;
use super::state::RunState;
use anyhow::Result;
use spacepose_bus::Bus;
use spacepose_eval::table::Table;
use spacepose_messages::{Health, Names, ServiceState, realtime_ns};
use std::io::Write;
use std::time::Duration;

/// Prints the status of `prefix` (every running deployment when `None`).
pub fn run(prefix: Option<&str>, out: &mut dyn Write) -> Result<()> {
    let states = match prefix {
        Some(p) => vec![RunState::load(p)?],
        None => RunState::all(),
    };
    if states.is_empty() {
        writeln!(out, "no running deployment")?;
        return Ok(());
    }
    for state in states {
        let names = Names::new(&state.prefix)?;
        let bus = Bus::open(&names, &format!("spacepose-status-{}", std::process::id()))?;
        let mut watch = HealthWatch::new(&bus, &names)?;
        // Two heartbeat periods: every live instance reports at least once.
        watch.collect_for(Duration::from_millis(2 * state.heartbeat_ms + 200))?;
        let age_s = super::state::unix_now_s() - state.started_unix_s;
        let supervisor = match state.supervisor_pid {
            Some(pid) if std::env::current_exe().is_ok_and(|e| is_alive(pid, &e)) => {
                format!("supervisor pid {pid}")
            }
            Some(pid) => format!("supervisor pid {pid} NOT RUNNING"),
            None => "no supervisor".to_string(),
        };
        writeln!(
            out,
            "deployment {:?}, started {:.0} s ago, {supervisor}, primary tracker: {}",
            state.prefix,
            age_s,
            state.primary.as_deref().unwrap_or("-")
        )?;
        write!(out, "{}", render(&state, &watch))?;
    }
    Ok(())
}

/// The status table of one deployment.
pub fn render(state: &RunState, watch: &HealthWatch) -> String {
    let mut t = Table::new(&[
        "instance",
        "kind",
        "role",
        "pid",
        "alive",
        "supervisor",
        "restarts",
        "health",
        "frames in",
        "frames out",
        "rejected",
        "errors",
        "last frame",
        "heartbeat age s",
    ]);
    let now_ns = realtime_ns();
    for i in &state.instances {
        let alive = is_alive(i.pid, &i.binary);
        let h = watch.get(&i.name).filter(|h| h.pid == i.pid);
        let dash = |v: &str| {
            if v.is_empty() {
                "-".to_string()
            } else {
                v.to_string()
            }
        };
        let mut row = vec![
            i.name.clone(),
            i.kind.to_string(),
            dash(&i.role),
            i.pid.to_string(),
            if alive { "yes" } else { "no" }.to_string(),
            dash(&i.status),
            i.restarts.to_string(),
        ];
        match h {
            Some(h) => row.extend(health_cells(h, now_ns)),
            None => row.extend(
                ["no heartbeat".to_string()]
                    .into_iter()
                    .chain(std::iter::repeat_n("-".to_string(), 4))
                    .chain([i.last_frame.map_or("-".to_string(), |f| f.to_string())])
                    .chain(["-".to_string()]),
            ),
        }
        t.row(row);
    }
    t.render()
}

fn health_cells(h: &Health, now_ns: i64) -> Vec<String> {
    let state = ServiceState::from_u8(h.state).map_or("?", ServiceState::as_str);
    let c = &h.counters;
    vec![
        state.to_string(),
        c.frames_in.to_string(),
        c.frames_out.to_string(),
        c.rejected().to_string(),
        c.errors.to_string(),
        c.last_frame.to_string(),
        format!("{:.2}", (now_ns - h.published_ns) as f64 * 1e-9),
    ]
}
