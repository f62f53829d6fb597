//! Tests of the ground tool's state: key splitting, message counting and
//! the rendered pose and health tables.

use super::*;

#[test]
fn keys_split_into_prefix_and_stream() {
    assert_eq!(
        split_key("spacepose/demo-1/telemetry/pose"),
        Some(("demo-1", "pose"))
    );
    assert_eq!(split_key("spacepose/demo-1/wire/pose"), None);
    assert_eq!(split_key("other/x/telemetry/pose"), None);
}

#[test]
fn messages_are_counted_and_malformed_ones_flagged() {
    let mut s = GroundState::default();
    assert_eq!(
        s.on_message("spacepose/p/telemetry/pose", b"not json"),
        Value::Null
    );
    assert_eq!(
        s.on_message("spacepose/p/telemetry/pose", b"{\"a\":1}"),
        json!({"a": 1})
    );
    assert_eq!(s.poses_received(), 2);
    assert_eq!(s.malformed, 2);
    s.on_message("spacepose/p/telemetry/filter", b"{}");
    assert_eq!(s.received["filter"], 1);
    s.on_message("spacepose/p/telemetry/health/ingest", b"{}");
    assert_eq!(s.received["health"], 1);
    assert!(s.render(Duration::from_secs(1)).contains("pose 2"));
}

/// A pose of `instance` at (3, 4, 12) m, i.e. 13 m away.
fn pose(instance: &str, latency_ms: Option<f64>) -> TelemetryPose {
    serde_json::from_value(json!({
        "schema_version": 4, "instance": instance, "sequence": 42, "t_s": 4.2,
        "status": "degraded", "mode": "track", "q_sensor_target": [1.0, 0.0, 0.0, 0.0],
        "p_sensor_target_m": [3.0, 4.0, 12.0], "euler_321_deg": [10.04, -20.06, 179.96],
        "sigma_rot_deg": [0.1, 0.1, 0.1], "sigma_pos_cm": [1.0, 1.0, 1.0],
        "cost": 0.5, "held_axes": 0, "held_translations": 0, "iterations": 7, "inliers": 100, "points_used": 200,
        "preprocess_ms": 1.0, "registration_ms": 2.0, "total_ms": 3.0,
        "latency_ms": latency_ms, "published_ns": 0
    }))
    .unwrap()
}

/// Errors of `instance` against truth.
fn errors(instance: &str, ang_err_deg: f64, pos_err_cm: f64) -> TelemetryErrors {
    serde_json::from_value(json!({
        "schema_version": 4, "instance": instance, "sequence": 42, "t_s": 4.2,
        "status": "degraded", "ang_err_deg": ang_err_deg, "pos_err_cm": pos_err_cm,
        "latency_ms": null
    }))
    .unwrap()
}

/// The whitespace-separated cells of the row of `prefix` and `instance`.
fn cells<'a>(text: &'a str, prefix: &str, instance: &str) -> Vec<&'a str> {
    let row = text
        .lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .find(|c| c.len() > 2 && c[0] == prefix && c[1] == instance);
    row.unwrap_or_else(|| panic!("no row {prefix} {instance} in\n{text}"))
}

#[test]
fn an_empty_state_renders_only_the_summary_line() {
    let mut s = GroundState::default();
    assert_eq!(
        s.render(Duration::from_millis(1500)),
        "-- ground 1.5 s: nothing yet (malformed 0)\n"
    );
    s.malformed = 3;
    s.received.insert("truth".into(), 2);
    s.received.insert("filter".into(), 5);
    assert_eq!(
        s.render(Duration::from_secs(60)),
        "-- ground 60.0 s: filter 5, truth 2 (malformed 3)\n"
    );
}

#[test]
fn pose_rows_show_range_and_the_errors_of_the_same_tracker() {
    let mut s = GroundState::default();
    let key = |i: &str| ("demo".to_string(), i.to_string());
    s.poses.insert(key("a"), pose("a", Some(1.234)));
    s.poses.insert(key("b"), pose("b", None));
    s.errors.insert(key("a"), errors("a", 0.126, 3.5));
    s.errors.insert(key("gone"), errors("gone", 9.0, 9.0));
    let text = s.render(Duration::ZERO);
    assert!(text.contains("latency ms"), "{text}");
    assert!(!text.contains("last frame"), "no health table yet:\n{text}");
    let a = [
        "demo", "a", "42", "degraded", "10.0", "-20.1", "180.0", "13.00",
    ];
    assert_eq!(
        cells(&text, "demo", "a"),
        [&a[..], &["0.13", "3.50", "1.23"]].concat()
    );
    let b = &cells(&text, "demo", "b");
    assert_eq!(b[..8], a.map(|c| if c == "a" { "b" } else { c }));
    assert_eq!(b[8..], ["-", "-", "-"]);
    assert!(
        !text.contains("gone"),
        "errors without a pose get no row:\n{text}"
    );
}

#[test]
fn health_rows_sum_every_kind_of_rejection() {
    let mut s = GroundState::default();
    let h: TelemetryHealth = serde_json::from_value(json!({
        "schema_version": 4, "service": "tracker", "instance": "t1", "state": "running",
        "pid": 7, "sequence": 3, "last_frame": 99, "uptime_s": 1.0, "frames_in": 120,
        "frames_out": 110, "rejected_non_finite": 1, "rejected_empty": 20,
        "rejected_oversized": 300, "rejected_wire": 4000, "errors": 5, "published_ns": 0
    }))
    .unwrap();
    s.health.insert(("demo".into(), "t1".into()), h);
    let text = s.render(Duration::ZERO);
    assert!(!text.contains("latency ms"), "no pose table yet:\n{text}");
    assert_eq!(
        cells(&text, "demo", "t1"),
        [
            "demo", "t1", "tracker", "running", "120", "110", "4321", "5", "99"
        ]
    );
}
