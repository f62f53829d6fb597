//! Fuzzed input through the real binaries: 10^4 garbage payloads on the
//! zenoh command key of `spacepose-telemetry` (random bytes, truncated,
//! trailing bytes, wrong magic, version, kind or schema field, oversized,
//! non-finite poses, bit flips of valid commands) and 2000 fuzzed raw
//! clouds into `spacepose-ingest` (empty, above capacity, every point
//! non-finite, non-finite or reversed scan interval). Both services stay
//! alive, and their health counters equal what was sent: every payload the
//! codec refuses is in telemetry's `rejected_wire`, every valid one (a bit
//! flip can stay valid) reaches the iceoryx2 command topic; every bad cloud
//! is in ingest's counter for its reason, and none comes out. An empty cloud
//! with a valid header is not bad input but the observation "target not
//! seen" (the sensor looked away; `spacepose_ingest` crate docs): each one
//! comes out as an empty cloud with its own header, counted in `frames_out`,
//! and `rejected_empty` stays 0.
#![allow(clippy::unwrap_used)] // test helpers

use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_bus::zenoh::Wait;
use spacepose_bus::zenoh::qos::CongestionControl;
use spacepose_bus::{Bus, Subscriber, ZenohConfig, open_zenoh};
use spacepose_e2e::net::listening_tcp;
use spacepose_e2e::*;
use spacepose_geometry::Point;
use spacepose_messages::codec::{ENVELOPE_LEN, MAGIC};
use spacepose_messages::{
    CloudHeader, Command, CommandKind, Health, Name, Names, SCHEMA_VERSION, ServiceState, Topic,
    WireMessage, decode, encode,
};
use std::collections::HashMap;
use std::path::Path;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

const WIRE_CASES: usize = 10_000;
const BAD_CLOUDS: u64 = 2_000;
const INGEST_MAX_POINTS: usize = 256;

struct Service(Child);

impl Drop for Service {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn start(name: &str, prefix: &str, config: &Path, heartbeat_ms: u32, log: &Path) -> Service {
    Service(
        std::process::Command::new(binary(name))
            .args([
                "--prefix",
                prefix,
                "--heartbeat-ms",
                &heartbeat_ms.to_string(),
                "--config",
            ])
            .arg(config)
            .env("RUST_LOG", "warn")
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(log).unwrap())
            .spawn()
            .unwrap(),
    )
}

/// Latest heartbeat per service kind.
struct Beats {
    health: Subscriber<Health>,
    latest: HashMap<String, Health>,
}

impl Beats {
    fn drain(&mut self) {
        while let Some(h) = self.health.try_recv().unwrap() {
            self.latest.insert(h.service.as_str().to_string(), h);
        }
    }

    fn wait(
        &mut self,
        what: &str,
        timeout: Duration,
        ok: impl Fn(&HashMap<String, Health>) -> bool,
    ) {
        let deadline = Instant::now() + timeout;
        loop {
            self.drain();
            if ok(&self.latest) {
                return;
            }
            assert!(
                Instant::now() < deadline,
                "timed out waiting for {what}: {:?}",
                self.latest
            );
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn of(&self, service: &str) -> Health {
        self.latest[service]
    }
}

fn valid_command(rng: &mut impl Rng, seq: u64) -> Command {
    let mut c = Command::new(CommandKind::Reinit, Name::new("fuzzer").unwrap());
    c.sequence = seq;
    c.target_instance = Name::new("tracker-z").unwrap();
    let q: [f64; 4] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    c.q_sensor_target = q.map(|v| v / n);
    c.p_sensor_target = [0.1, -0.2, 10.0];
    c
}

fn noise(rng: &mut impl Rng, n: usize) -> Vec<u8> {
    (0..n).map(|_| rng.random::<u8>()).collect()
}

/// One garbage (or possibly valid, for bit flips) payload.
fn payload(rng: &mut impl Rng, i: u64, other_kind: &[u8]) -> Vec<u8> {
    let valid = encode(&valid_command(rng, i)).unwrap();
    let len = valid.len();
    let mut b = valid.clone();
    match rng.random_range(0..10) {
        0 => {
            let n = rng.random_range(0..400);
            noise(rng, n)
        }
        1 => valid[..rng.random_range(0..len)].to_vec(),
        2 => {
            let n = rng.random_range(1..9);
            b.extend(noise(rng, n));
            b
        }
        3 => {
            b[2..4].copy_from_slice(&(SCHEMA_VERSION + rng.random_range(1..100)).to_le_bytes());
            b
        }
        4 => other_kind.to_vec(), // a valid message of another kind
        5 => {
            b[rng.random_range(0..2)] ^= rng.random_range(1..=255u8);
            b
        }
        6 => {
            let n = Command::MAX_WIRE_BYTES + rng.random_range(1..200);
            noise(rng, n)
        }
        7 => {
            b[ENVELOPE_LEN] = 0; // schema field 0 (a Default-built message)
            b
        }
        8 => {
            // A NaN or infinite pose, encoded without validation.
            let mut c = valid_command(rng, i);
            let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][rng.random_range(0..3)];
            c.p_sensor_target[rng.random_range(0..3)] = bad;
            let mut out = MAGIC.to_vec();
            out.extend_from_slice(&SCHEMA_VERSION.to_le_bytes());
            out.push(Command::KIND);
            out.extend(postcard_body(&c));
            out
        }
        _ => {
            for _ in 0..rng.random_range(1..9) {
                let at = rng.random_range(0..len);
                b[at] ^= 1 << rng.random_range(0..8);
            }
            b
        }
    }
}

/// The postcard body of a command (the codec's encoder would refuse a
/// non-finite pose, so it is written by hand from a valid encoding).
fn postcard_body(c: &Command) -> Vec<u8> {
    // Encode with finite stand-ins, then patch the f64 fields: postcard
    // writes f64 as 8 little-endian bytes, and the pose is the tail of the
    // struct (q then p).
    let mut finite = *c;
    finite.p_sensor_target = [0.0; 3];
    let bytes = encode(&finite).unwrap();
    let mut body = bytes[ENVELOPE_LEN..].to_vec();
    let tail = body.len() - 24;
    for (k, v) in c.p_sensor_target.iter().enumerate() {
        body[tail + 8 * k..tail + 8 * k + 8].copy_from_slice(&v.to_le_bytes());
    }
    body
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum CloudReason {
    Empty,
    Oversized,
    NonFinite,
    BadInterval,
}

fn bad_cloud(rng: &mut impl Rng) -> (Vec<Point>, f64, f64, CloudReason) {
    let n = rng.random_range(1..INGEST_MAX_POINTS);
    let finite = |rng: &mut ChaCha8Rng, i: usize| {
        Point::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            10.0,
            0.5,
            i as f64 * 1e-4,
        )
    };
    let mut r = ChaCha8Rng::seed_from_u64(rng.random());
    match rng.random_range(0..4) {
        0 => (Vec::new(), 0.0, 0.1, CloudReason::Empty),
        1 => {
            let n = INGEST_MAX_POINTS + rng.random_range(1..64);
            (
                (0..n).map(|i| finite(&mut r, i)).collect(),
                0.0,
                0.1,
                CloudReason::Oversized,
            )
        }
        2 => {
            let pts = (0..n)
                .map(|i| {
                    let mut p = finite(&mut r, i);
                    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][r.random_range(0..3)];
                    match r.random_range(0..4) {
                        0 => p.x = bad,
                        1 => p.y = bad,
                        2 => p.z = bad,
                        _ => p.t = f64::from(bad),
                    }
                    p
                })
                .collect();
            (pts, 0.0, 0.1, CloudReason::NonFinite)
        }
        _ => {
            // Some of them empty: a bad header is bad input, points or not.
            let n = if rng.random_range(0..4) == 0 { 0 } else { n };
            let (a, b) =
                [(f64::NAN, 0.1), (0.0, f64::INFINITY), (0.3, 0.1)][rng.random_range(0..3)];
            (
                (0..n).map(|i| finite(&mut r, i)).collect(),
                a,
                b,
                CloudReason::BadInterval,
            )
        }
    }
}

#[test]
fn ten_thousand_garbage_payloads_and_bad_clouds_are_refused_counted_and_survived() {
    let dir = scratch_dir("fuzz-input");
    let prefix = unique_prefix("fuzz");
    let names = Names::new(&prefix).unwrap();
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let tconf = dir.join("telemetry.toml");
    std::fs::write(&tconf, format!("[zenoh]\nlisten = [\"{endpoint}\"]\n")).unwrap();
    let iconf = dir.join("ingest.toml");
    std::fs::write(&iconf, format!("max_points = {INGEST_MAX_POINTS}\n")).unwrap();

    let bus = Bus::open(&names, "e2e-fuzz").unwrap();
    let commands = bus.subscriber::<Command>(&names.command()).unwrap();
    let raw = bus
        .cloud_publisher(&names.raw_cloud(), 4 * INGEST_MAX_POINTS)
        .unwrap();
    let cropped = bus.cloud_subscriber(&names.cloud()).unwrap();
    let mut beats = Beats {
        health: bus.subscriber::<Health>(&names.health()).unwrap(),
        latest: HashMap::new(),
    };
    let mut telemetry = start(
        "spacepose-telemetry",
        &prefix,
        &tconf,
        50,
        &dir.join("telemetry.log"),
    );
    let mut ingest = start(
        "spacepose-ingest",
        &prefix,
        &iconf,
        5,
        &dir.join("ingest.log"),
    );
    beats.wait("both heartbeats", Duration::from_secs(30), |l| {
        l.contains_key("telemetry") && l.contains_key("ingest")
    });
    for s in [&telemetry, &ingest] {
        let l = listening_tcp(s.0.id());
        assert!(
            l.iter().all(|a| a.ip().is_loopback()),
            "listening beyond loopback: {l:?}"
        );
    }

    // --- zenoh: garbage on the command key ---------------------------------
    let session = open_zenoh(&ZenohConfig::client(&[&endpoint])).unwrap();
    let key = names.wire_key(Topic::Command);
    let publisher = session
        .declare_publisher(key)
        .congestion_control(CongestionControl::Block)
        .wait()
        .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(0xbad_c0de);
    // The route is up once a valid command comes through.
    let mut warmup = 0;
    let deadline = Instant::now() + Duration::from_secs(20);
    'route: loop {
        warmup += 1;
        publisher
            .put(encode(&valid_command(&mut rng, 0)).unwrap())
            .wait()
            .unwrap();
        std::thread::sleep(Duration::from_millis(50));
        if commands.try_recv().unwrap().is_some() {
            break 'route;
        }
        assert!(Instant::now() < deadline, "no command came through");
    }
    std::thread::sleep(Duration::from_millis(200));
    while commands.try_recv().unwrap().is_some() {}
    let base = beats.of("telemetry").counters.rejected_wire;
    assert_eq!(base, 0);

    let mut health_msg = Health::new(Name::new("x").unwrap(), Name::new("y").unwrap(), 1);
    health_msg.sequence = 1;
    let other_kind = encode(&health_msg).unwrap();
    let (mut expected_rejected, mut expected_forwarded, mut forwarded) = (0u64, 0u64, 0u64);
    let started = Instant::now();
    for i in 0..WIRE_CASES as u64 {
        let bytes = payload(&mut rng, i, &other_kind);
        let valid = decode::<Command>(&bytes).is_ok();
        publisher.put(bytes).wait().unwrap();
        if valid {
            // A bit flip that is still a valid command: it must arrive.
            expected_forwarded += 1;
            let deadline = Instant::now() + Duration::from_secs(10);
            while forwarded < expected_forwarded {
                if commands.try_recv().unwrap().is_some() {
                    forwarded += 1;
                } else {
                    assert!(Instant::now() < deadline, "valid payload {i} not forwarded");
                    std::thread::sleep(Duration::from_micros(200));
                }
            }
        } else {
            expected_rejected += 1;
        }
    }
    let sent_s = started.elapsed().as_secs_f64();
    beats.wait("telemetry's rejected_wire", Duration::from_secs(30), |l| {
        l["telemetry"].counters.rejected_wire >= expected_rejected
    });
    std::thread::sleep(Duration::from_millis(300));
    beats.drain();
    while commands.try_recv().unwrap().is_some() {
        forwarded += 1;
    }
    let t = beats.of("telemetry");
    assert_eq!(t.counters.rejected_wire, expected_rejected);
    assert_eq!(forwarded, expected_forwarded);
    assert_eq!(t.state, ServiceState::Running as u8);
    println!(
        "zenoh: {WIRE_CASES} payloads in {sent_s:.1} s: {expected_rejected} refused and counted \
         (rejected_wire {}), {expected_forwarded} bit flips still valid and forwarded ({warmup} \
         warm-up commands before)",
        t.counters.rejected_wire
    );

    // --- iceoryx2: bad raw clouds into ingest ------------------------------
    let before = beats.of("ingest");
    let mut expected: HashMap<&str, u64> = HashMap::new();
    // (sequence, scan start, scan end) of the empty clouds sent and received.
    let (mut empty_sent, mut empty_out) = (Vec::new(), Vec::new());
    let drain_cropped = |out: &mut Vec<(u64, f64, f64)>| {
        while let Some(c) = cropped.try_recv().unwrap() {
            let h = *c.header();
            assert_eq!(
                (h.point_count, c.len()),
                (0, 0),
                "a non-empty cloud came out"
            );
            out.push((h.sequence, h.scan_start_s, h.scan_end_s));
        }
    };
    let started = Instant::now();
    for seq in 0..BAD_CLOUDS {
        // At most two frames in flight (the subscriber buffer): wait for
        // ingest's heartbeat (every 5 ms) to show the one before last.
        beats.wait("ingest to keep up", Duration::from_secs(30), |l| {
            l["ingest"].counters.frames_in + 1 >= before.counters.frames_in + seq
        });
        let (points, start_s, end_s, reason) = bad_cloud(&mut rng);
        let name = match reason {
            CloudReason::Empty => "empty",
            CloudReason::Oversized => "oversized",
            CloudReason::NonFinite => "non_finite",
            CloudReason::BadInterval => "errors",
        };
        *expected.entry(name).or_default() += 1;
        if reason == CloudReason::Empty {
            empty_sent.push((seq, start_s, end_s));
        }
        raw.send(CloudHeader::new(seq, start_s, end_s), &points)
            .unwrap();
        // Each empty cloud is collected before the next one is sent (the
        // subscriber buffers two clouds; nothing else comes out).
        if reason == CloudReason::Empty {
            let deadline = Instant::now() + Duration::from_secs(10);
            while empty_out.len() < empty_sent.len() {
                assert!(Instant::now() < deadline, "empty cloud {seq} not forwarded");
                std::thread::sleep(Duration::from_micros(200));
                drain_cropped(&mut empty_out);
            }
        }
    }
    beats.wait("ingest to take every frame", Duration::from_secs(30), |l| {
        l["ingest"].counters.frames_in >= before.counters.frames_in + BAD_CLOUDS
    });
    let clouds_s = started.elapsed().as_secs_f64();
    let i = beats.of("ingest");
    drain_cropped(&mut empty_out);
    let e = |k: &str| expected.get(k).copied().unwrap_or(0);
    assert_eq!(i.counters.frames_in - before.counters.frames_in, BAD_CLOUDS);
    // Empty clouds with a valid header: forwarded, each with its own header.
    assert!(e("empty") > 0);
    assert_eq!(
        i.counters.frames_out - before.counters.frames_out,
        e("empty"),
        "only the empty clouds come out"
    );
    assert_eq!(empty_out, empty_sent, "the empty clouds as sent");
    assert_eq!(i.counters.rejected_empty, before.counters.rejected_empty);
    assert_eq!(
        i.counters.rejected_oversized - before.counters.rejected_oversized,
        e("oversized")
    );
    assert_eq!(
        i.counters.rejected_non_finite - before.counters.rejected_non_finite,
        e("non_finite")
    );
    assert_eq!(i.counters.errors - before.counters.errors, e("errors"));
    assert_eq!(i.state, ServiceState::Running as u8);
    println!(
        "ingest: {BAD_CLOUDS} fuzzed clouds in {clouds_s:.1} s: {} empty ones with a valid header \
         forwarded empty with their header, every other one refused and counted: {expected:?}",
        empty_out.len()
    );

    // Both alive, and ingest still passes a good frame.
    let good: Vec<Point> = (0..100)
        .map(|k| Point::new(0.01 * k as f32, 0.0, 10.0, 0.5, k as f64 * 1e-3))
        .collect();
    raw.send(CloudHeader::new(BAD_CLOUDS, 0.0, 0.1), &good)
        .unwrap();
    beats.wait(
        "a good frame through ingest",
        Duration::from_secs(10),
        |l| l["ingest"].counters.frames_out == before.counters.frames_out + e("empty") + 1,
    );
    assert!(telemetry.0.try_wait().unwrap().is_none(), "telemetry died");
    assert!(ingest.0.try_wait().unwrap().is_none(), "ingest died");
}
