//! `spacepose up` with broken descriptors: it says what is wrong and starts
//! nothing (no process, no state file).
#![allow(clippy::unwrap_used)] // test helpers

use spacepose_e2e::*;

const SIM: &str =
    "[[service]]\nname = \"sim\"\nkind = \"lidar-sim\"\nconfig = { truth_init = true }\n";
const INGEST: &str = "[[service]]\nname = \"ingest\"\nkind = \"ingest\"\n";
const TRACKER: &str = "[[service]]\nname = \"tracker\"\nkind = \"tracker\"\n";

fn up_fails(name: &str, body: &str, expected: &[&str]) {
    let dir = scratch_dir(&format!("broken-{name}"));
    let prefix = unique_prefix(name);
    let _down = DownOnDrop(prefix.clone());
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, format!("prefix = \"{prefix}\"\n{body}")).unwrap();
    let o = spacepose(&["up", file.to_str().unwrap()]);
    let all = text(&o);
    assert!(!o.status.success(), "{name}: up succeeded\n{all}");
    assert_eq!(o.status.code(), Some(2), "{all}");
    let stderr = String::from_utf8_lossy(&o.stderr);
    for e in expected {
        assert!(
            stderr.contains(e),
            "{name}: {e:?} not in the message\n{all}"
        );
    }
    assert!(!stderr.contains("panicked"), "{all}");
    assert!(
        !state_file(&prefix).exists(),
        "{name}: a state file was written"
    );
    let left = processes_mentioning(&prefix);
    assert!(left.is_empty(), "{name}: processes remain: {left:?}");
}

#[test]
fn broken_descriptors_start_nothing() {
    require_suite();
    up_fails(
        "unknown-key",
        &format!("colour = \"red\"\n{SIM}{INGEST}"),
        &["colour"],
    );
    up_fails(
        "unknown-service-key",
        &format!("{SIM}{INGEST}replicas = 2\n"),
        &["replicas"],
    );
    up_fails(
        "unknown-kind",
        &format!("{SIM}[[service]]\nname = \"x\"\nkind = \"radar\"\n"),
        &["radar"],
    );
    up_fails(
        "missing-binary",
        &format!("{SIM}{INGEST}binary = \"/nonexistent/spacepose-ingest\"\n"),
        &["/nonexistent/spacepose-ingest", "\"ingest\""],
    );
    up_fails(
        "topic-mismatch",
        &format!("{SIM}{TRACKER}"),
        &["\"tracker\"", "\"cloud\"", "add one of: ingest"],
    );
    up_fails("no-sensor", INGEST, &["\"raw_cloud\"", "lidar-sim"]);
    up_fails(
        "duplicate",
        &format!("{SIM}{INGEST}{INGEST}"),
        &["used twice"],
    );
    up_fails(
        "bad-config",
        &format!("{SIM}{INGEST}config = {{ not_a_field = 1 }}\n"),
        &["\"ingest\"", "invalid config", "not_a_field"],
    );
}
