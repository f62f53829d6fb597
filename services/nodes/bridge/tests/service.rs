//! The `spacepose-bridge` binary as real processes: two "hosts" on one
//! machine (their own iceoryx2 prefixes) joined by a loopback link with
//! accounts. Host a listens, checks host b's account, forwards poses to
//! the link and waits for b before its first heartbeat; host b connects
//! with its account and forwards the link's poses to its own bus.
#![allow(clippy::unwrap_used)] // tests may unwrap

use spacepose_bus::{Bus, Publisher, Subscriber};
use spacepose_messages::{Health, Name, Names, PoseEstimate, ServiceState, WireStatus};
use spacepose_runtime::testing::{self, ChildGuard};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn wait_for<T>(what: &str, f: impl FnMut() -> Option<T>) -> T {
    testing::wait_for(what, Duration::from_secs(20), f)
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn bridge(prefix: &str, config: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_spacepose-bridge"));
    c.args(["--prefix", prefix, "--heartbeat-ms", "50", "--config"])
        .arg(config)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    c
}

/// The newest heartbeat of the bridge for which `pred` holds.
fn beat(sub: &Subscriber<Health>, what: &str, pred: impl Fn(&Health) -> bool) -> Health {
    wait_for(what, || {
        let mut found = None;
        while let Some(h) = sub.try_recv().unwrap() {
            if h.service.as_str() == "bridge" && pred(&h) {
                found = Some(h);
            }
        }
        found
    })
}

fn pose(seq: u64) -> PoseEstimate {
    let mut e = PoseEstimate::new();
    e.sequence = seq;
    e.status = WireStatus::Tracking as u8;
    e.instance = Name::new("tracker-a").unwrap();
    e.p_sensor_target = [0.0, 0.0, 12.0];
    e.published_ns = spacepose_messages::realtime_ns();
    e
}

/// Sends poses on a until b has `n` of them; returns their sequences.
fn relay(poses: &Publisher<PoseEstimate>, got: &Subscriber<PoseEstimate>, n: usize) -> Vec<u64> {
    let mut seen = Vec::new();
    let mut seq = 0;
    wait_for("poses across the link", || {
        seq += 1;
        poses.send(&pose(seq)).unwrap();
        std::thread::sleep(Duration::from_millis(20));
        while let Some(p) = got.try_recv().unwrap() {
            seen.push(p.sequence);
        }
        (seen.len() >= n).then(|| seen.clone())
    })
}

fn terminate(child: &mut ChildGuard) -> std::process::ExitStatus {
    let pid = child.0.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    wait_for("the bridge's exit", || child.0.try_wait().unwrap())
}

/// Host a's and host b's configurations (and their accounts) in `dir`.
fn write_configs(dir: &Path, endpoint: &str) {
    let d = |f: &str| dir.join(f).display().to_string();
    std::fs::write(dir.join("users"), "host-b:pw-b\n").unwrap();
    std::fs::write(dir.join("b.account"), "host-b:pw-b\n").unwrap();
    let a = format!(
        "suite_prefix = \"orbit\"\nwait_for_link_s = 15.0\nstats_file = {:?}\n\
         [zenoh]\nlisten = [\"{endpoint}\"]\n[access]\ndictionary_file = {:?}\npeers = [\"host-b\"]\n\
         [[routes]]\ntopic = \"pose\"\ndirection = \"to-zenoh\"\n",
        d("a.stats.json"),
        d("users")
    );
    let b = format!(
        "suite_prefix = \"orbit\"\ncredentials_file = {:?}\nstats_file = {:?}\nstats_period_s = 0.2\n\
         [zenoh]\nconnect = [\"{endpoint}\"]\n[[routes]]\ntopic = \"pose\"\ndirection = \"from-zenoh\"\n",
        d("b.account"),
        d("b.stats.json")
    );
    std::fs::write(dir.join("a.toml"), a).unwrap();
    std::fs::write(dir.join("b.toml"), b).unwrap();
}

/// Starts a bridge in the background.
fn spawn(prefix: &str, config: &Path) -> ChildGuard {
    ChildGuard(
        bridge(prefix, config)
            .stdout(Stdio::null())
            .spawn()
            .unwrap(),
    )
}

/// `--check` accepts the configuration.
fn check_ok(config: &Path) {
    let out = bridge("brcheck", config).arg("--check").output().unwrap();
    assert!(out.status.success(), "{out:?}");
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "configuration ok"
    );
}

/// frames_in, frames_out, rejected_wire, errors.
fn counted(h: &Health) -> (u64, u64, u64, u64) {
    let c = &h.counters;
    (c.frames_in, c.frames_out, c.rejected_wire, c.errors)
}

fn read_json(path: &Path) -> Option<serde_json::Value> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

#[test]
fn two_hosts_exchange_poses_with_accounts_and_report_their_counters() {
    let (pa, pb) = (testing::unique_prefix("bra"), testing::unique_prefix("brb"));
    let dir = tempfile::tempdir().unwrap();
    let d = |f: &str| dir.path().join(f);
    write_configs(dir.path(), &format!("tcp/127.0.0.1:{}", free_port()));
    check_ok(&d("a.toml"));
    check_ok(&d("b.toml"));
    let (names_a, names_b) = (Names::new(&pa).unwrap(), Names::new(&pb).unwrap());
    let bus_a = Bus::open(&names_a, "test-a").unwrap();
    let bus_b = Bus::open(&names_b, "test-b").unwrap();
    let health_a = bus_a.subscriber::<Health>(&names_a.health()).unwrap();
    let health_b = bus_b.subscriber::<Health>(&names_b.health()).unwrap();
    let poses = bus_a.publisher::<PoseEstimate>(&names_a.pose()).unwrap();
    let got = bus_b.subscriber::<PoseEstimate>(&names_b.pose()).unwrap();
    let mut a = spawn(&pa, &d("a.toml"));
    // a waits for a subscriber of its pose route: no heartbeat before b is up.
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        health_a.try_recv().unwrap().is_none(),
        "a did not wait for b"
    );
    assert!(a.0.try_wait().unwrap().is_none(), "a gave up");
    let mut b = spawn(&pb, &d("b.toml"));
    beat(&health_a, "a's first heartbeat", |_| true);
    let seqs = relay(&poses, &got, 5);
    assert!(seqs.windows(2).all(|w| w[0] < w[1]), "{seqs:?}");
    let ha = beat(&health_a, "a's frames_out", |h| h.counters.frames_out >= 5);
    let hb = beat(&health_b, "b's frames_in", |h| h.counters.frames_in >= 5);
    assert_eq!(ha.state, ServiceState::Running as u8);
    assert_eq!((counted(&ha).0, counted(&ha).2, counted(&ha).3), (0, 0, 0));
    assert_eq!((counted(&hb).1, counted(&hb).2, counted(&hb).3), (0, 0, 0));
    // b rewrites its statistics every 0.2 s.
    wait_for("b's statistics", || {
        let v = read_json(&d("b.stats.json"))?;
        (v["forwarded_from_zenoh"].as_u64()? >= 5).then_some(v)
    });
    for (child, health) in [(&mut b, &health_b), (&mut a, &health_a)] {
        assert!(terminate(child).success());
        beat(health, "the Stopping heartbeat", |h| {
            h.state == ServiceState::Stopping as u8
        });
    }
    // Written on the way out at the latest (a's period is 2 s).
    let sa = read_json(&d("a.stats.json")).unwrap();
    assert!(sa["forwarded_to_zenoh"].as_u64().unwrap() >= 5, "{sa}");
    assert_eq!(sa["routes"], serde_json::json!(["pose ToZenoh"]));
    assert_eq!(sa["rejected_wire"], 0);
}

#[test]
fn an_admitted_account_missing_from_the_dictionary_stops_the_start() {
    let dir = tempfile::tempdir().unwrap();
    let d = |f: &str| dir.path().join(f);
    std::fs::write(d("users"), "host-b:pw-b\n").unwrap();
    std::fs::write(
        d("a.toml"),
        format!(
            "suite_prefix = \"orbit\"\n[zenoh]\nlisten = [\"tcp/127.0.0.1:{}\"]\n\
             [access]\ndictionary_file = {:?}\npeers = [\"host-c\"]\n",
            free_port(),
            d("users").display().to_string()
        ),
    )
    .unwrap();
    let prefix = testing::unique_prefix("brc");
    let out = bridge(&prefix, &d("a.toml"))
        .arg("--check")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let out = bridge(&prefix, &d("a.toml")).output().unwrap();
    assert!(
        !out.status.success(),
        "started with an account missing from the dictionary"
    );
    std::fs::write(d("users"), "host-c:pw-c\n").unwrap();
    let out = bridge(&prefix, &d("a.toml"))
        .arg("--check")
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
}
