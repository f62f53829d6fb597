//! Tests of descriptor validation: start order, topic mismatches, names,
//! binaries, timing and the per-binary config check.

use super::*;

fn search() -> BinarySearch {
    BinarySearch {
        exe_dir: None,
        path: vec![],
        base_dir: PathBuf::from("/bin"),
    }
}

fn descriptor(body: &str) -> Descriptor {
    let mut text = String::from("prefix = \"t\"\n");
    for line in body.lines() {
        let (name, kind) = line.split_once(' ').unwrap();
        text.push_str(&format!(
            "[[service]]\nname = \"{name}\"\nkind = \"{kind}\"\nbinary = \"/bin/sh\"\n"
        ));
        if kind == "lidar-sim" {
            text.push_str("config = { truth_init = true }\n");
        }
    }
    Descriptor::parse(&text).unwrap()
}

#[test]
fn a_full_suite_plans_with_sources_last() {
    let d = descriptor(
        "sim lidar-sim\ningest ingest\ntracker tracker\nfilter filter\ntelemetry telemetry",
    );
    let p = plan(&d, &search(), ConfigCheck::Skip).unwrap();
    let (first, last) = p.start_order();
    assert_eq!(first.len(), 4);
    assert_eq!(last[0].name, "sim");
    let t = p
        .instances
        .iter()
        .find(|i| i.kind == ServiceKind::Telemetry)
        .unwrap();
    assert_eq!(
        t.config["zenoh"]["listen"][0].as_str(),
        Some(super::super::descriptor::DEFAULT_LISTEN)
    );
    // A restarted sensor resumes from its checkpoint in the run dir.
    let sim = last[0].config["checkpoint_file"].as_str().unwrap();
    assert!(sim.ends_with("/sim.sensorstate"), "{sim}");
}

#[test]
fn topic_mismatches_are_named() {
    let e = plan(
        &descriptor("tracker tracker\nfilter filter"),
        &search(),
        ConfigCheck::Skip,
    )
    .unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("\"cloud\"") && text.contains("add one of: ingest"),
        "{text}"
    );
    assert!(text.contains("truth_init"), "{text}");
    let e = plan(&descriptor("ingest ingest"), &search(), ConfigCheck::Skip).unwrap_err();
    assert!(e.to_string().contains("raw_cloud"), "{e}");
}

#[test]
fn duplicate_and_bad_names_and_missing_binaries_are_reported_together() {
    let mut d = descriptor("sim lidar-sim\nsim ingest\nBad_Name filter");
    d.services[2].binary = Some(PathBuf::from("/nonexistent/spacepose-filter"));
    let e = plan(&d, &search(), ConfigCheck::Skip).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("used twice"), "{text}");
    assert!(text.contains("\"Bad_Name\""), "{text}");
    assert!(text.contains("/nonexistent/spacepose-filter"), "{text}");
    assert!(text.contains("\"pose\""), "{text}");
}

#[test]
fn descriptor_level_problems_are_listed_in_order() {
    let d = Descriptor::parse(
        "prefix = \"Bad Prefix\"\nheartbeat_ms = 0\nhealth_timeout_s = -1.0\n\
         hang_timeout_ms = 0\n[restart]\nwindow_s = 0.0\n\
         [[service]]\nname = \"ingest\"\nkind = \"ingest\"\nbinary = \"/bin/sh\"\nhost = \"a\"\n",
    )
    .unwrap();
    let e = plan(&d, &search(), ConfigCheck::Skip).unwrap_err();
    let prefix = Names::new("Bad Prefix").unwrap_err();
    assert_eq!(
        e.0[..6],
        [
            format!("prefix: {prefix}"),
            "service \"ingest\" names a host, but the descriptor has no [[host]] tables"
                .to_string(),
            "health_timeout_s must be a positive number of seconds, got -1".to_string(),
            "heartbeat_ms must be >= 1".to_string(),
            "hang_timeout_ms must be longer than heartbeat_ms".to_string(),
            "restart.window_s must be a positive number of seconds, got 0".to_string(),
        ]
    );
    // Then the topic check: ingest's raw_cloud has no producer.
    assert_eq!(e.0.len(), 7, "{e}");
    assert!(e.0[6].contains("raw_cloud"), "{e}");
    assert!(
        e.to_string()
            .starts_with("the deployment descriptor has 7 problem(s):")
    );
}

#[test]
fn an_empty_or_partitioned_descriptor_is_refused() {
    let e = plan(
        &Descriptor::parse("prefix = \"t\"\n").unwrap(),
        &search(),
        ConfigCheck::Skip,
    )
    .unwrap_err();
    assert_eq!(e.0, ["no [[service]] entries"]);
    let mut d = descriptor("sim lidar-sim\ningest ingest");
    let hosts =
        Descriptor::parse("prefix = \"t\"\n[[host]]\nname = \"a\"\n[[host]]\nname = \"b\"\n")
            .unwrap()
            .hosts;
    d.hosts = hosts;
    d.services[0].host = Some("a".into());
    let e = plan(&d, &search(), ConfigCheck::Skip).unwrap_err();
    // Only the partition is reported, not the service's host.
    assert_eq!(e.0.len(), 1, "{e}");
    assert!(
        e.0[0].starts_with("the descriptor is partitioned over hosts a, b: ")
            && e.0[0].ends_with("`spacepose up --host NAME`"),
        "{e}"
    );
}

#[test]
fn timeouts_and_restart_policies_come_from_the_descriptor() {
    let mut d = descriptor("sim lidar-sim\ningest ingest");
    d.heartbeat_ms = 200;
    d.health_timeout_s = 2.5;
    d.restart.policy = Policy::Always;
    d.restart.max_restarts = 2;
    d.services[1].restart_policy = Some(Policy::Never);
    let p = plan(&d, &search(), ConfigCheck::Skip).unwrap();
    assert_eq!(p.names.prefix(), "t");
    assert_eq!(p.heartbeat_ms, 200);
    assert_eq!(p.health_timeout, Duration::from_millis(2500));
    // Default: 3 heartbeat periods + 100 ms.
    assert_eq!(p.hang_timeout, Duration::from_millis(700));
    assert_eq!(p.restart, d.restart);
    assert_eq!(p.zenoh, d.zenoh);
    let names: Vec<&str> = p.instances.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["sim", "ingest"]);
    assert_eq!(p.instances[0].restart_policy, Policy::Always);
    assert_eq!(p.instances[1].restart_policy, Policy::Never);
    assert_eq!(p.instances[1].binary, PathBuf::from("/bin/sh"));
    d.hang_timeout_ms = Some(201);
    let p = plan(&d, &search(), ConfigCheck::Skip).unwrap();
    assert_eq!(p.hang_timeout, Duration::from_millis(201));
}

#[test]
fn config_check_runs_each_binary_only_when_asked() {
    let mut d = descriptor("sim lidar-sim\ningest ingest");
    d.services[0].binary = Some(PathBuf::from("/bin/true"));
    d.services[1].binary = Some(PathBuf::from("/bin/false"));
    let e = plan(&d, &search(), ConfigCheck::Run).unwrap_err();
    assert_eq!(
        e.0,
        ["service \"ingest\" (ingest): invalid config: /bin/false --check failed (exit status: 1)"]
    );
    assert!(plan(&d, &search(), ConfigCheck::Skip).is_ok());
    d.services[1].binary = Some(PathBuf::from("/bin/true"));
    assert!(plan(&d, &search(), ConfigCheck::Run).is_ok());
}
