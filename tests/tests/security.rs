//! zenoh access control of the ground link, through the real telemetry
//! binary (which hosts the zenoh -> iceoryx2 command bridge):
//! - peers without an account, or with a wrong password, cannot even open a
//!   link, so their commands go nowhere;
//! - a reader account reads telemetry (subscription and the `latest`
//!   queryable) but its commands are dropped by the ACL before the bridge:
//!   none reaches the iceoryx2 command topic, and the bridge never sees them
//!   (`rejected_wire` stays 0: zenoh 1.10 does not report ACL drops to the
//!   application without its `stats` feature);
//! - an operator account's command reaches the iceoryx2 command topic, and
//!   the garbage it sends is refused by the codec and counted;
//! - the service listens on loopback only.
#![allow(clippy::unwrap_used)] // test helpers

use spacepose_bus::zenoh::Wait;
use spacepose_bus::zenoh::qos::CongestionControl;
use spacepose_bus::{Bus, Credentials, Subscriber, ZenohConfig, open_zenoh, open_zenoh_with};
use spacepose_e2e::net::listening_tcp;
use spacepose_e2e::*;
use spacepose_messages::{
    Command, CommandKind, Health, Name, Names, PoseEstimate, Topic, WireStatus, encode,
};
use std::process::{Child, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Kills the service when the test ends, whatever happened.
struct Service(Child);

impl Drop for Service {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn wait_until<T>(what: &str, timeout: Duration, mut f: impl FnMut() -> Option<T>) -> T {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(v) = f() {
            return v;
        }
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn client(
    endpoint: &str,
    account: Option<&Credentials>,
) -> Result<spacepose_bus::zenoh::Session, String> {
    open_zenoh_with(&ZenohConfig::client(&[endpoint]), |c| match account {
        Some(a) => a.apply(c),
        None => Ok(()),
    })
    .map_err(|e| e.to_string())
}

fn command(issued_by: &str, sequence: u64) -> Vec<u8> {
    let mut c = Command::new(CommandKind::Mode, Name::new(issued_by).unwrap());
    c.mode = 2;
    c.sequence = sequence;
    encode(&c).unwrap()
}

/// Latest heartbeat of the telemetry instance.
fn telemetry_health(health: &Subscriber<Health>, latest: &mut Option<Health>) {
    while let Some(h) = health.try_recv().unwrap() {
        if h.service.as_str() == "telemetry" {
            *latest = Some(h);
        }
    }
}

#[test]
fn only_operators_send_commands_and_readers_still_read_telemetry() {
    let telemetry = binary("spacepose-telemetry");
    let dir = scratch_dir("security");
    let prefix = unique_prefix("sec");
    let names = Names::new(&prefix).unwrap();
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let users = dir.join("users.txt");
    std::fs::write(&users, "op:op-secret\nground:ground-pass\n").unwrap();
    let config = dir.join("telemetry.toml");
    std::fs::write(
        &config,
        format!(
            "[zenoh]\nlisten = [\"{endpoint}\"]\n[access]\ndictionary_file = \"{}\"\n\
             operators = [\"op\"]\nreaders = [\"ground\"]\n",
            users.display()
        ),
    )
    .unwrap();

    let bus = Bus::open(&names, "e2e-security").unwrap();
    let commands = bus.subscriber::<Command>(&names.command()).unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let poses = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let log = std::fs::File::create(dir.join("telemetry.log")).unwrap();
    let mut service = Service(
        std::process::Command::new(telemetry)
            .args(["--prefix", &prefix, "--heartbeat-ms", "50", "--config"])
            .arg(&config)
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .unwrap(),
    );
    let mut latest = None;
    wait_until(
        "telemetry's first heartbeat",
        Duration::from_secs(30),
        || {
            telemetry_health(&health, &mut latest);
            latest
        },
    );

    // Loopback only.
    let listening = listening_tcp(service.0.id());
    assert!(!listening.is_empty(), "telemetry listens nowhere");
    assert!(
        listening.iter().all(|a| a.ip().is_loopback()),
        "telemetry listens beyond loopback: {listening:?}"
    );

    // No account, or a wrong password: the handshake is refused.
    let Err(e) = client(&endpoint, None) else {
        panic!("an anonymous client connected");
    };
    println!("anonymous client refused: {e}");
    let Err(e) = client(&endpoint, Some(&Credentials::new("op", "guess"))) else {
        panic!("a wrong password connected");
    };
    println!("wrong password refused: {e}");
    // An anonymous *peer* opens a session (it retries in the background) but
    // has no link: its commands go nowhere.
    let mut anon_peer = ZenohConfig::loopback(free_port());
    anon_peer.connect.push(endpoint.clone());
    let anon = open_zenoh(&anon_peer).ok();

    // A reader: telemetry flows, the latest queryable answers.
    let reader = client(&endpoint, Some(&Credentials::new("ground", "ground-pass"))).unwrap();
    let (tx, rx) = mpsc::channel::<String>();
    let _sub = reader
        .declare_subscriber(names.telemetry_key("pose"))
        .callback(move |s| {
            let _ = tx.send(String::from_utf8_lossy(&s.payload().to_bytes()).into_owned());
        })
        .wait()
        .unwrap();
    let mut seq = 0;
    let json = wait_until(
        "a pose on the reader's subscription",
        Duration::from_secs(20),
        || {
            seq += 1;
            let mut e = PoseEstimate::new();
            e.sequence = seq;
            e.status = WireStatus::Tracking as u8;
            e.instance = Name::new("tracker-s").unwrap();
            e.p_sensor_target = [0.0, 0.0, 10.0];
            poses.send(&e).unwrap();
            rx.recv_timeout(Duration::from_millis(100)).ok()
        },
    );
    assert!(json.contains("\"sequence\""), "{json}");
    let replies = reader
        .get(names.telemetry_key("latest"))
        .timeout(Duration::from_secs(5))
        .wait()
        .unwrap();
    let reply = replies
        .recv_timeout(Duration::from_secs(5))
        .unwrap()
        .unwrap();
    let latest_json = reply.result().unwrap().payload().to_bytes().into_owned();
    assert!(!latest_json.is_empty());

    // The reader and the anonymous peer try to command: nothing gets through.
    let key = names.wire_key(Topic::Command);
    let reader_pub = reader
        .declare_publisher(key.clone())
        .congestion_control(CongestionControl::Block)
        .wait()
        .unwrap();
    for i in 0..25 {
        reader_pub.put(command("ground", i)).wait().unwrap();
        if let Some(anon) = &anon {
            anon.put(key.clone(), command("anonymous", i))
                .wait()
                .unwrap();
        }
        std::thread::sleep(Duration::from_millis(40));
    }

    // The operator's command gets through (re-sent until the subscription
    // has propagated), and its garbage is counted.
    let operator = client(&endpoint, Some(&Credentials::new("op", "op-secret"))).unwrap();
    let mut sent = 0;
    let seen = wait_until(
        "the operator's command on iceoryx2",
        Duration::from_secs(20),
        || {
            sent += 1;
            operator
                .put(key.clone(), command("op", 1000 + sent))
                .wait()
                .unwrap();
            std::thread::sleep(Duration::from_millis(50));
            let mut got = Vec::new();
            while let Some(c) = commands.try_recv().unwrap() {
                got.push(c);
            }
            (!got.is_empty()).then_some(got)
        },
    );
    let mut all: Vec<Command> = seen;
    for _ in 0..5 {
        operator
            .put(key.clone(), b"not a command".to_vec())
            .wait()
            .unwrap();
    }
    telemetry_health(&health, &mut latest);
    let counted = wait_until(
        "the operator's garbage counted",
        Duration::from_secs(10),
        || {
            telemetry_health(&health, &mut latest);
            latest.filter(|h| h.counters.rejected_wire >= 5)
        },
    );
    // Only the operator's 5 garbage payloads: the reader's and the anonymous
    // peer's commands never reached the bridge.
    assert_eq!(counted.counters.rejected_wire, 5);
    while let Some(c) = commands.try_recv().unwrap() {
        all.push(c);
    }
    let issuers: Vec<&str> = all.iter().map(|c| c.issued_by.as_str()).collect();
    assert!(
        issuers.iter().all(|i| *i == "op"),
        "commands from {issuers:?}"
    );
    assert_eq!(all[0].kind, CommandKind::Mode as u8);
    println!(
        "operator: {} command(s) forwarded ({} sent until the route was up); reader and \
         anonymous peer: 25 commands each, 0 forwarded; rejected_wire {}",
        all.len(),
        sent,
        counted.counters.rejected_wire
    );
    assert!(service.0.try_wait().unwrap().is_none(), "telemetry died");
}
