//! A partitioned run (issue 7): deploy/partitioned.toml on three "hosts"
//! of one machine. Host a (lidar-sim, ingest) and the ground host
//! (telemetry) each reach only host b (tracker, filter; the zenoh router)
//! over their own veth pair in their own network namespace, so the poses
//! computed on b from a's clouds, and a's truth, can reach the ground's
//! telemetry only across the zenoh link (through the router for a -> ground).
//! Each host's part runs under its own iceoryx2 prefix, started with
//! `spacepose up --host NAME`; the link requires the hosts' accounts.
//!
//! Where network namespaces are not allowed (not root, no CAP_SYS_ADMIN),
//! or `SPACEPOSE_E2E_NO_NETNS` is set, the same three parts run as separate
//! zenoh sessions on loopback ports, and the test says so on stderr.
//!
//! Needs the release binaries, spacepose-bridge included.
#![allow(clippy::unwrap_used, clippy::expect_used)] // test code

use serde_json::Value;
use spacepose_e2e::{DownOnDrop, binary, free_port, repo_root, scratch_dir, spacepose, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// Runs `ip args…`; Err carries its stderr.
fn ip(args: &[&str]) -> Result<(), String> {
    let o = Command::new("ip")
        .args(args)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("running ip: {e}"))?;
    if o.status.success() {
        Ok(())
    } else {
        Err(format!(
            "ip {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&o.stderr).trim()
        ))
    }
}

/// Three network namespaces, a and ground each linked to b by a veth pair;
/// deleted on drop.
struct Namespaces {
    names: Vec<String>,
}

impl Drop for Namespaces {
    fn drop(&mut self) {
        for n in &self.names {
            let _ = ip(&["netns", "del", n]);
        }
    }
}

/// Addresses of b on the a link and on the ground link.
const B_ONBOARD: &str = "10.231.1.2";
const B_GROUND: &str = "10.231.2.2";

fn namespaces(tag: &str) -> Result<Namespaces, String> {
    let mut ns = Namespaces { names: Vec::new() };
    for host in ["a", "b", "g"] {
        let name = format!("{tag}{host}");
        ip(&["netns", "add", &name])?;
        ns.names.push(name);
    }
    let (a, b, g) = (&ns.names[0], &ns.names[1], &ns.names[2]);
    let steps: Vec<Vec<String>> = [
        format!("link add {tag}a0 type veth peer name {tag}b0"),
        format!("link set {tag}a0 netns {a}"),
        format!("link set {tag}b0 netns {b}"),
        format!("link add {tag}g0 type veth peer name {tag}b1"),
        format!("link set {tag}g0 netns {g}"),
        format!("link set {tag}b1 netns {b}"),
        format!("-n {a} addr add 10.231.1.1/24 dev {tag}a0"),
        format!("-n {b} addr add {B_ONBOARD}/24 dev {tag}b0"),
        format!("-n {b} addr add {B_GROUND}/24 dev {tag}b1"),
        format!("-n {g} addr add 10.231.2.1/24 dev {tag}g0"),
        format!("-n {a} link set {tag}a0 up"),
        format!("-n {b} link set {tag}b0 up"),
        format!("-n {b} link set {tag}b1 up"),
        format!("-n {g} link set {tag}g0 up"),
        format!("-n {a} link set lo up"),
        format!("-n {b} link set lo up"),
        format!("-n {g} link set lo up"),
    ]
    .iter()
    .map(|s| s.split(' ').map(str::to_string).collect())
    .collect();
    for step in steps {
        let args: Vec<&str> = step.iter().map(String::as_str).collect();
        ip(&args)?;
    }
    Ok(ns)
}

/// How a host's commands are run: in its namespace, or directly.
#[derive(Clone)]
struct Host {
    netns: Option<String>,
}

impl Host {
    fn command(&self, program: &Path) -> Command {
        match &self.netns {
            Some(ns) => {
                let mut c = Command::new("ip");
                c.args(["netns", "exec", ns]).arg(program);
                c
            }
            None => Command::new(program),
        }
    }

    fn spacepose(&self, args: &[&str]) -> std::process::Output {
        self.command(&binary("spacepose"))
            .args(args)
            .current_dir(repo_root())
            .stdin(Stdio::null())
            .output()
            .expect("running spacepose")
    }
}

fn write_private(path: &Path, text: &str) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::write(path, text).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o600)).unwrap();
}

/// deploy/partitioned.toml with this run's prefix, endpoints and accounts.
fn descriptor(
    dir: &Path,
    suite: &str,
    onboard: &str,
    ground_link: &str,
    telemetry: &str,
) -> PathBuf {
    let nonce = format!("{:x}", std::process::id() ^ 0x5eed);
    let dict = dir.join("link-users");
    write_private(
        &dict,
        &format!("host-a:pa-{nonce}\nhost-b:pb-{nonce}\nground:pg-{nonce}\n"),
    );
    write_private(&dir.join("host-a.account"), &format!("host-a:pa-{nonce}\n"));
    write_private(&dir.join("ground.account"), &format!("ground:pg-{nonce}\n"));
    let text = std::fs::read_to_string(repo_root().join("deploy/partitioned.toml")).unwrap();
    let text = text
        .replace("\"orbit\"", &format!("\"{suite}\""))
        .replace("192.168.10.2:7450", onboard)
        .replace("192.168.20.2:7450", ground_link)
        .replace("127.0.0.1:7447", telemetry)
        .replace("/etc/spacepose/", &format!("{}/", dir.display()))
        .replace("wait_for_link_s = 60.0", "wait_for_link_s = 20.0");
    let path = dir.join("partitioned.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn read_json(path: &Path) -> Value {
    let t = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&t).unwrap()
}

fn run_dir(prefix: &str) -> PathBuf {
    std::env::temp_dir().join("spacepose").join(prefix)
}

fn net_ns_of(pid: u64) -> Option<PathBuf> {
    std::fs::read_link(format!("/proc/{pid}/ns/net")).ok()
}

fn pid_of(prefix: &str, instance: &str) -> u64 {
    let s = read_json(&run_dir(prefix).join("state.json"));
    s["instances"]
        .as_array()
        .unwrap()
        .iter()
        .find(|i| i["name"] == instance)
        .and_then(|i| i["pid"].as_u64())
        .unwrap_or_else(|| panic!("{instance} not in the state of {prefix}: {s}"))
}

#[test]
fn poses_cross_the_zenoh_link_to_the_ground() {
    for b in [
        "spacepose-bridge",
        "spacepose-lidar-sim",
        "spacepose-ingest",
        "spacepose-tracker",
        "spacepose-init",
        "spacepose-filter",
        "spacepose-telemetry",
    ] {
        binary(b);
    }
    let started = Instant::now();
    let tag = format!("sp{}", std::process::id() % 100_000);
    let suite = format!("pt{}", std::process::id() % 100_000);
    let dir = scratch_dir(&format!("partitioned-{suite}"));
    let telemetry_port = free_port();
    let telemetry = format!("127.0.0.1:{telemetry_port}");
    let probe = format!("{tag}probe");
    let netns = match std::env::var_os("SPACEPOSE_E2E_NO_NETNS") {
        Some(_) => Err("SPACEPOSE_E2E_NO_NETNS is set".to_string()),
        None => ip(&["netns", "add", &probe]).and_then(|()| ip(&["netns", "del", &probe])),
    };
    let (ns, hosts, onboard, ground_link) = match netns {
        Ok(()) => {
            let ns = namespaces(&tag).expect("setting up the namespaces");
            let hosts: Vec<Host> = ns
                .names
                .iter()
                .map(|n| Host {
                    netns: Some(n.clone()),
                })
                .collect();
            (
                Some(ns),
                hosts,
                format!("{B_ONBOARD}:7450"),
                format!("{B_GROUND}:7450"),
            )
        }
        Err(why) => {
            eprintln!(
                "NOTE: network namespaces are not available here ({why}); running the three \
                 hosts as separate zenoh sessions on loopback instead (same descriptor, \
                 same bridges and accounts, no network isolation)"
            );
            let local = Host { netns: None };
            (
                None,
                vec![local.clone(), local.clone(), local],
                format!("127.0.0.1:{}", free_port()),
                format!("127.0.0.1:{}", free_port()),
            )
        }
    };
    let (host_a, host_b, host_g) = (&hosts[0], &hosts[1], &hosts[2]);
    let deploy = descriptor(&dir, &suite, &onboard, &ground_link, &telemetry);
    let deploy_arg = deploy.display().to_string();
    let (prefix_a, prefix_b) = (format!("{suite}-a"), format!("{suite}-b"));
    // Dropped before the namespaces (declared after them).
    let _downs = [
        DownOnDrop(prefix_a.clone()),
        DownOnDrop(suite.clone()),
        DownOnDrop(prefix_b.clone()),
    ];
    // b first (the router), then the ground, then a (waits for both).
    let up = |host: &Host, name: &str| {
        let o = host.spacepose(&["up", &deploy_arg, "--host", name]);
        assert!(o.status.success(), "up --host {name}: {}", text(&o));
    };
    up(host_b, "b");
    up(host_g, "ground");
    let record = dir.join("ground.jsonl");
    let recorder = host_g
        .command(&binary("spacepose"))
        .args(["ground", "--connect", &format!("tcp/{telemetry}")])
        .args(["--prefix", &suite, "--duration", "14", "--record"])
        .arg(&record)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting the ground tool");
    up(host_a, "a");
    if ns.is_some() {
        // Really on three network stacks.
        let (a, b, g) = (
            net_ns_of(pid_of(&prefix_a, "ingest")),
            net_ns_of(pid_of(&prefix_b, "tracker")),
            net_ns_of(pid_of(&suite, "telemetry")),
        );
        assert!(
            a.is_some() && a != b && b != g && a != g,
            "{a:?} {b:?} {g:?}"
        );
    }
    let out = recorder.wait_with_output().unwrap();
    for prefix in [&prefix_a, &prefix_b, &suite] {
        let o = spacepose(&["down", "--prefix", prefix]);
        assert!(o.status.success(), "down {prefix}: {}", text(&o));
    }
    let lines: Vec<Value> = std::fs::read_to_string(&record)
        .unwrap_or_default()
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    let of = |what: &str| -> Vec<&Value> {
        let key = format!("spacepose/{suite}/telemetry/{what}");
        lines.iter().filter(|l| l["key"] == key.as_str()).collect()
    };
    let poses = of("pose");
    let tracking = poses
        .iter()
        .filter(|p| p["payload"]["status"] == "tracking")
        .count();
    let truth = of("truth").len();
    let stats = |prefix: &str, host: &str| {
        read_json(&run_dir(prefix).join(format!("bridge-{host}.stats.json")))
    };
    let (sa, sb, sg) = (
        stats(&prefix_a, "a"),
        stats(&prefix_b, "b"),
        stats(&suite, "ground"),
    );
    let mut latency: Vec<f64> = poses
        .iter()
        .filter_map(|p| p["payload"]["latency_ms"].as_f64())
        .collect();
    latency.sort_by(f64::total_cmp);
    let median = latency.get(latency.len() / 2).copied().unwrap_or(f64::NAN);
    println!(
        "partitioned run ({}): {} poses at the ground ({tracking} tracking), {truth} truth; \
         cloud on b -> pose at the ground median {median:.1} ms; link transit (mean/max ms): \
         cloud a->b {}/{}, pose b->ground {}/{}, filter_state b->a {}/{}, health ->ground {}/{}; \
         {:.1} s",
        if ns.is_some() {
            "network namespaces"
        } else {
            "loopback"
        },
        poses.len(),
        sb["latency_from_zenoh"]["cloud"]["mean_ms"],
        sb["latency_from_zenoh"]["cloud"]["max_ms"],
        sg["latency_from_zenoh"]["pose"]["mean_ms"],
        sg["latency_from_zenoh"]["pose"]["max_ms"],
        sa["latency_from_zenoh"]["filter_state"]["mean_ms"],
        sa["latency_from_zenoh"]["filter_state"]["max_ms"],
        sg["latency_from_zenoh"]["health"]["mean_ms"],
        sg["latency_from_zenoh"]["health"]["max_ms"],
        started.elapsed().as_secs_f64()
    );
    let context = format!(
        "ground tool: {}\nstats a {sa}\nstats b {sb}\nstats ground {sg}",
        String::from_utf8_lossy(&out.stderr)
    );
    // 30 frames; init acquires on b from a's clouds, tracking follows.
    assert!(
        tracking >= 20,
        "{tracking} tracking poses at the ground\n{context}"
    );
    assert!(
        truth >= 20,
        "a's truth reached the ground via b: {truth}\n{context}"
    );
    assert!(
        sb["latency_from_zenoh"]["cloud"]["samples"].as_u64() >= Some(25),
        "{context}"
    );
    assert!(
        sa["latency_from_zenoh"]["filter_state"]["samples"].as_u64() >= Some(1),
        "{context}"
    );
    for s in [&sa, &sb, &sg] {
        assert_eq!(s["rejected_wire"], 0, "{context}");
    }
    drop(ns);
}
