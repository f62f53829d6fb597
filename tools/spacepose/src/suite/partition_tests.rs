//! Tests of the split of a partitioned descriptor into host parts: each
//! host's services, bridge and crossing topics, and host problems.

use super::*;

pub(crate) const PARTITIONED: &str = r#"
prefix = "orbit"
[link]
dictionary_file = "link-users"
peers = ["host-a", "host-b", "ground"]
[[host]]
name = "a"
mode = "client"
connect = ["tcp/10.0.0.2:7450"]
credentials_file = "/etc/sp/a"
wait_for_link_s = 30.0
[[host]]
name = "b"
mode = "router"
listen = ["tcp/10.0.0.2:7450"]
[[host]]
name = "ground"
prefix = "orbit"
mode = "client"
connect = ["tcp/10.0.0.2:7450"]
[[service]]
name = "lidar-sim"
kind = "lidar-sim"
host = "a"
config = { truth_init = true }
[[service]]
name = "ingest"
kind = "ingest"
host = "a"
[[service]]
name = "tracker"
kind = "tracker"
host = "b"
[[service]]
name = "filter"
kind = "filter"
host = "b"
[[service]]
name = "telemetry"
kind = "telemetry"
host = "ground"
"#;

fn routes(part: &Descriptor) -> Vec<(String, String)> {
    let b = part
        .services
        .iter()
        .find(|s| s.kind == ServiceKind::Bridge)
        .unwrap();
    b.config["routes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["topic"].as_str().unwrap().to_string(),
                r["direction"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

fn pairs(v: &[(&str, &str)]) -> Vec<(String, String)> {
    v.iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect()
}

#[test]
fn each_host_gets_its_services_a_bridge_and_the_crossing_topics() {
    let d = Descriptor::parse(PARTITIONED).unwrap();
    let base = Path::new("/deploy");
    let a = host_part(&d, "a", base).unwrap();
    assert_eq!(a.prefix, "orbit-a");
    let names: Vec<&str> = a.services.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["lidar-sim", "ingest", "bridge-a"]);
    // The sensor host sends clouds, its truth acquisition, truth and
    // health; it receives the filter state (ROI). No service of it reads
    // commands (the topic graph), so none cross to it.
    assert_eq!(
        routes(&a),
        pairs(&[
            ("cloud", "to-zenoh"),
            ("filter_state", "from-zenoh"),
            ("acquisition", "to-zenoh"),
            ("truth", "to-zenoh"),
            ("health", "to-zenoh"),
        ])
    );
    let bridge = a.services.last().unwrap();
    assert_eq!(bridge.config["suite_prefix"].as_str(), Some("orbit"));
    assert_eq!(bridge.config["zenoh"]["mode"].as_str(), Some("client"));
    assert_eq!(
        bridge.config["credentials_file"].as_str(),
        Some("/etc/sp/a")
    );
    assert_eq!(
        bridge.config["access"]["dictionary_file"].as_str(),
        Some("/deploy/link-users")
    );
    let b = host_part(&d, "b", base).unwrap();
    assert_eq!(
        routes(&b),
        pairs(&[
            ("cloud", "from-zenoh"),
            ("pose", "to-zenoh"),
            ("filter_state", "to-zenoh"),
            ("acquisition", "from-zenoh"),
            ("health", "to-zenoh"),
            ("command", "from-zenoh"),
        ])
    );
    let g = host_part(&d, "ground", base).unwrap();
    assert_eq!(g.prefix, "orbit");
    assert_eq!(
        routes(&g),
        pairs(&[
            ("pose", "from-zenoh"),
            ("filter_state", "from-zenoh"),
            ("truth", "from-zenoh"),
            ("health", "from-zenoh"),
            ("command", "to-zenoh"),
        ])
    );
    // Each part plans on its own: the bridge provides what comes from
    // the other hosts.
    let search = super::super::binaries::BinarySearch {
        exe_dir: None,
        path: vec![],
        base_dir: PathBuf::from("/bin"),
    };
    for mut part in [a, b, g] {
        for s in &mut part.services {
            s.binary = Some(PathBuf::from("/bin/sh"));
        }
        super::super::plan::plan(&part, &search, super::super::plan::ConfigCheck::Skip).unwrap();
    }
}

#[test]
fn host_problems_are_reported_together() {
    let d = Descriptor::parse(PARTITIONED).unwrap();
    let e = host_part(&d, "c", Path::new("/")).unwrap_err().to_string();
    assert!(e.contains("unknown host \"c\""), "{e}");
    let bad = PARTITIONED
        .replacen("host = \"b\"", "host = \"x\"", 1)
        .replace(
            "name = \"ground\"\nprefix = \"orbit\"",
            "name = \"ground\"\nprefix = \"orbit-a\"",
        );
    let e = host_part(&Descriptor::parse(&bad).unwrap(), "a", Path::new("/"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown host \"x\""), "{e}");
    assert!(e.contains("same local prefix"), "{e}");
    // A tracker on the sensor host as well: poses produced on two hosts,
    // and b needs a's... both ways on b.
    let both = format!(
        "{PARTITIONED}[[service]]\nname = \"init\"\nkind = \"init\"\nhost = \"ground\"\n\
         [[service]]\nname = \"filter-g\"\nkind = \"filter\"\nhost = \"ground\"\n"
    );
    let e = host_part(&Descriptor::parse(&both).unwrap(), "b", Path::new("/"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("both ways"), "{e}");
    let flat = Descriptor::parse("prefix = \"p\"\n").unwrap();
    assert!(host_part(&flat, "a", Path::new("/")).is_err());
}
