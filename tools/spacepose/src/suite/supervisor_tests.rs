//! Unit tests of how the supervisor handles exited processes
//! (`Supervisor::check_exits`), with real child processes and a real bus
//! node under a prefix of each test's own.

use super::*;
use crate::suite::descriptor::ZenohEndpoints;
use crate::suite::launch::RunningSuite;
use crate::suite::process::{is_alive, signal_group};
use crate::suite::restart::{Policy, RestartSettings};
use crate::suite::state::{RunState, run_dir, unix_now_s};
use crate::suite::swap::SwapHost;
use rustix::process::Signal;
use std::path::{Path, PathBuf};

/// Delay of every first restart of the test suites.
const BACKOFF: Duration = Duration::from_millis(40);

/// A shell script that runs until it is killed (ignoring its arguments).
fn long_running(dir: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let p = dir.join("svc");
    std::fs::write(&p, "#!/bin/sh\nsleep 30\n").unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    p
}

/// The plan of `services` (name, binary, restart policy) under the prefix
/// `tsup{pid}{tag}`: restarts after [`BACKOFF`], at most `max_restarts`.
fn test_plan(tag: &str, services: &[(&str, &Path, Policy)], max_restarts: u32) -> Plan {
    let names = Names::new(&format!("tsup{}{tag}", std::process::id())).unwrap();
    Plan {
        names,
        heartbeat_ms: 100,
        health_timeout: Duration::from_secs(5),
        hang_timeout: Duration::from_secs(1),
        restart: RestartSettings {
            backoff_ms: BACKOFF.as_millis() as u64,
            max_restarts,
            ..RestartSettings::default()
        },
        zenoh: ZenohEndpoints::default(),
        instances: services
            .iter()
            .map(|(name, binary, policy)| PlannedInstance {
                name: name.to_string(),
                kind: ServiceKind::Ingest,
                binary: binary.to_path_buf(),
                config: toml::Table::new(),
                restart_policy: *policy,
            })
            .collect(),
    }
}

/// A supervisor of `plan`, every instance started (a spawn that races
/// another test's script write, `ETXTBSY`, is retried).
fn supervisor(plan: Plan) -> Supervisor {
    let names = plan.names.clone();
    std::fs::create_dir_all(run_dir(names.prefix())).unwrap();
    let bus = Bus::open(&names, "supervisor-test").unwrap();
    let watch = HealthWatch::new(&bus, &names).unwrap();
    let mut suite = RunningSuite::empty(RunState {
        prefix: names.prefix().to_string(),
        heartbeat_ms: plan.heartbeat_ms,
        started_unix_s: unix_now_s(),
        started_by_pid: std::process::id(),
        supervisor_pid: None,
        primary: None,
        instances: Vec::new(),
    });
    for i in &plan.instances {
        let mut tries = 0;
        while let Err(e) = suite.spawn_instance(&plan, i) {
            tries += 1;
            assert!(tries < 50, "{e:#}");
            std::thread::sleep(Duration::from_millis(10));
        }
    }
    Supervisor::new(plan, bus, watch, suite).unwrap()
}

/// Waits until the processes of `names` have exited (not reaped).
fn wait_exited(sup: &Supervisor, names: &[&str]) {
    let deadline = Instant::now() + Duration::from_secs(10);
    for name in names {
        let inst = &sup.suite.state.instances[sup.suite.index(name).unwrap()];
        while is_alive(inst.pid, &inst.binary) {
            assert!(Instant::now() < deadline, "{name} still runs");
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

/// Kills what still runs, stops the suite and removes its run directory.
fn finish(mut sup: Supervisor) {
    let names: Vec<String> = sup
        .suite
        .state
        .instances
        .iter()
        .map(|i| i.name.clone())
        .collect();
    for name in names {
        if sup.suite.try_exit(&name).is_none() {
            signal_group(sup.suite.pid(&name).unwrap(), Signal::KILL);
        }
    }
    let prefix = sup.plan.names.prefix().to_string();
    sup.stop(&mut Vec::new()).unwrap();
    let _ = std::fs::remove_dir_all(run_dir(&prefix));
}

/// Runs `check_exits` at `now`; returns what it wrote.
fn check_exits(sup: &mut Supervisor, now: Instant) -> String {
    let mut out = Vec::new();
    sup.check_exits(now, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

/// Status of every instance (in memory).
fn statuses(sup: &Supervisor) -> Vec<(String, String)> {
    sup.suite
        .state
        .instances
        .iter()
        .map(|i| (i.name.clone(), i.status.clone()))
        .collect()
}

/// (instance, cause, decision) of every fault.
fn faults(sup: &Supervisor) -> Vec<(&str, &str, &str)> {
    sup.faults
        .iter()
        .map(|f| (f.instance.as_str(), f.cause.as_str(), f.decision.as_str()))
        .collect()
}

/// A fault detected at `at`, nothing decided yet.
fn fault(instance: &str, cause: &str, at: Instant) -> Fault {
    Fault {
        instance: instance.into(),
        cause: cause.into(),
        detected_at: at,
        restarted_at: None,
        healthy_at: None,
        decision: String::new(),
    }
}

#[test]
fn exits_are_faults_restarted_or_left_by_the_policy() {
    let dir = tempfile::tempdir().unwrap();
    let (t, f) = (Path::new("/bin/true"), Path::new("/bin/false"));
    let runs = long_running(dir.path());
    let plan = test_plan(
        "exits",
        &[
            ("fails", f, Policy::OnFailure),
            ("clean", t, Policy::OnFailure),
            ("always", t, Policy::Always),
            ("never", f, Policy::Never),
            ("unplanned", f, Policy::OnFailure),
            ("norecord", f, Policy::OnFailure),
            ("waiting", f, Policy::OnFailure),
            ("runs", &runs, Policy::OnFailure),
        ],
        5,
    );
    let mut sup = supervisor(plan);
    // Not planned (any more): its policy is `never`.
    sup.plan.instances.retain(|i| i.name != "unplanned");
    sup.records.remove("norecord");
    let later = Instant::now() + Duration::from_secs(3600);
    sup.records.get_mut("waiting").unwrap().restart_at = Some(later);
    let exiting = [
        "fails",
        "clean",
        "always",
        "never",
        "unplanned",
        "norecord",
        "waiting",
    ];
    wait_exited(&sup, &exiting);
    let now = Instant::now();
    assert_eq!(
        check_exits(&mut sup, now),
        "supervisor: fails exit: exit status: 1 -> restart in 40 ms\n\
         supervisor: clean exit: exit status: 0 -> leave\n\
         supervisor: always exit: exit status: 0 -> restart in 40 ms\n\
         supervisor: never exit: exit status: 1 -> leave\n\
         supervisor: unplanned exit: exit status: 1 -> leave\n\
         supervisor: norecord exit: exit status: 1 -> restart in 40 ms\n"
    );
    assert_eq!(
        faults(&sup),
        [
            ("fails", "exit: exit status: 1", "restart"),
            ("clean", "exit: exit status: 0", "leave"),
            ("always", "exit: exit status: 0", "restart"),
            ("never", "exit: exit status: 1", "leave"),
            ("unplanned", "exit: exit status: 1", "leave"),
            ("norecord", "exit: exit status: 1", "restart"),
        ]
    );
    assert!(
        sup.faults
            .iter()
            .all(|f| f.detected_at == now && f.restarted_at.is_none() && f.healthy_at.is_none())
    );
    let expected: Vec<(String, String)> = [
        ("fails", "restarting"),
        ("clean", "exited"),
        ("always", "restarting"),
        ("never", "failed"),
        ("unplanned", "failed"),
        ("norecord", "restarting"),
        ("waiting", "running"),
        ("runs", "running"),
    ]
    .iter()
    .map(|(n, s)| (n.to_string(), s.to_string()))
    .collect();
    assert_eq!(statuses(&sup), expected);
    // Saved: state.json has the same statuses.
    let saved = RunState::load(sup.plan.names.prefix()).unwrap();
    let saved: Vec<(String, String)> = saved
        .instances
        .iter()
        .map(|i| (i.name.clone(), i.status.clone()))
        .collect();
    assert_eq!(saved, expected);
    for (name, restart_at, open_fault) in [
        ("fails", Some(now + BACKOFF), Some(0)),
        ("clean", None, None),
        ("always", Some(now + BACKOFF), Some(2)),
        ("never", None, None),
        ("norecord", Some(now + BACKOFF), Some(5)),
        ("waiting", Some(later), None),
    ] {
        let r = &sup.records[name];
        assert_eq!(
            (r.restart_at, r.open_fault),
            (restart_at, open_fault),
            "{name}"
        );
        assert_eq!(r.healthy, name == "waiting", "{name}");
        assert!(!r.killed_for_hang, "{name}");
    }
    finish(sup);
}

#[test]
fn too_many_restarts_give_up() {
    let plan = test_plan(
        "giveup",
        &[
            ("fails", Path::new("/bin/false"), Policy::OnFailure),
            ("clean", Path::new("/bin/true"), Policy::Always),
        ],
        0,
    );
    let mut sup = supervisor(plan);
    wait_exited(&sup, &["fails", "clean"]);
    let now = Instant::now();
    assert_eq!(
        check_exits(&mut sup, now),
        "supervisor: fails exit: exit status: 1 -> give up\n\
         supervisor: clean exit: exit status: 0 -> give up\n"
    );
    assert_eq!(
        faults(&sup),
        [
            ("fails", "exit: exit status: 1", "give up"),
            ("clean", "exit: exit status: 0", "give up"),
        ]
    );
    let st = statuses(&sup);
    assert_eq!(st[0].1, "failed");
    assert_eq!(st[1].1, "failed");
    for name in ["fails", "clean"] {
        let r = &sup.records[name];
        assert_eq!((r.restart_at, r.open_fault), (None, None), "{name}");
    }
    // Given up: the next steps do not report the same exit again.
    assert_eq!(check_exits(&mut sup, now + Duration::from_secs(1)), "");
    assert_eq!(sup.faults.len(), 2);
    finish(sup);
}

#[test]
fn an_instance_left_down_is_not_a_new_fault_at_every_step() {
    let plan = test_plan(
        "leftdown",
        &[
            ("clean", Path::new("/bin/true"), Policy::OnFailure),
            ("never", Path::new("/bin/false"), Policy::Never),
        ],
        5,
    );
    let mut sup = supervisor(plan);
    wait_exited(&sup, &["clean", "never"]);
    let now = Instant::now();
    assert_eq!(
        check_exits(&mut sup, now),
        "supervisor: clean exit: exit status: 0 -> leave\n\
         supervisor: never exit: exit status: 1 -> leave\n"
    );
    for step in 1..4 {
        let later = now + Duration::from_secs(step);
        assert_eq!(check_exits(&mut sup, later), "", "step {step}");
    }
    assert_eq!(sup.faults.len(), 2);
    let st = statuses(&sup);
    assert_eq!((st[0].1.as_str(), st[1].1.as_str()), ("exited", "failed"));
    // Swapped out while down: forgotten as any retired instance is.
    sup.retire("never");
    assert_eq!(
        check_exits(&mut sup, now + Duration::from_secs(5)),
        "supervisor: never stopped (exit status: 1)\n"
    );
    assert_eq!(statuses(&sup).len(), 1);
    assert_eq!(sup.faults.len(), 2);
    finish(sup);
}

#[test]
fn a_retired_instance_is_forgotten_without_a_fault() {
    let plan = test_plan(
        "retire",
        &[
            ("old", Path::new("/bin/true"), Policy::Always),
            ("other", Path::new("/bin/true"), Policy::Never),
        ],
        5,
    );
    let mut sup = supervisor(plan);
    sup.records.get_mut("old").unwrap().retiring = true;
    wait_exited(&sup, &["old", "other"]);
    assert_eq!(
        check_exits(&mut sup, Instant::now()),
        "supervisor: old stopped (exit status: 0)\n\
         supervisor: other exit: exit status: 0 -> leave\n"
    );
    assert!(sup.suite.index("old").is_none());
    assert!(!sup.records.contains_key("old"));
    assert_eq!(faults(&sup), [("other", "exit: exit status: 0", "leave")]);
    finish(sup);
}

#[test]
fn the_exit_of_a_hung_instance_completes_its_fault() {
    let plan = test_plan(
        "hung",
        &[
            ("hung", Path::new("/bin/true"), Policy::OnFailure),
            ("again", Path::new("/bin/false"), Policy::OnFailure),
        ],
        5,
    );
    let mut sup = supervisor(plan);
    let before = Instant::now();
    // `hung` was killed for hanging (fault 0); `again` was restarted after
    // fault 1 and has sent no heartbeat yet.
    sup.faults.push(fault("hung", "hung", before));
    sup.faults.push(Fault {
        decision: "restart".into(),
        ..fault("again", "exit: signal: 9 (SIGKILL)", before)
    });
    let r = sup.records.get_mut("hung").unwrap();
    (r.killed_for_hang, r.open_fault) = (true, Some(0));
    sup.records.get_mut("again").unwrap().open_fault = Some(1);
    wait_exited(&sup, &["hung", "again"]);
    let now = Instant::now();
    // A clean exit after a hang is a failure: restarted.
    assert_eq!(
        check_exits(&mut sup, now),
        "supervisor: hung hung -> restart in 40 ms\n\
         supervisor: again exit: exit status: 1 -> restart in 40 ms\n"
    );
    assert_eq!(
        faults(&sup),
        [
            ("hung", "hung", "restart"),
            ("again", "exit: signal: 9 (SIGKILL)", "restart"),
            ("again", "exit: exit status: 1", "restart"),
        ]
    );
    assert_eq!(sup.faults[0].detected_at, before);
    assert_eq!(sup.faults[2].detected_at, now);
    for (name, open_fault) in [("hung", Some(0)), ("again", Some(2))] {
        let r = &sup.records[name];
        assert_eq!(r.open_fault, open_fault, "{name}");
        assert_eq!(r.restart_at, Some(now + BACKOFF), "{name}");
        assert!(!r.killed_for_hang && !r.healthy, "{name}");
    }
    assert_eq!(statuses(&sup)[0].1, "restarting");
    finish(sup);
}
