//! One frame path: the same simulated frames through the running suite
//! (lidar-sim, ingest, tracker and filter processes over iceoryx2) and
//! through `eval tracking`'s deployed harness (the same nodes on an
//! in-memory bus), from the same truth acquisition of the first frame,
//! give the same published poses.
//!
//! Both paths simulate the frames with the sensor's own frame source and
//! configuration (every sensor effect on, no clutter, an integration time
//! of one frame period), crop with the target's crop, compensate and
//! voxel-filter in the tracker's one pipeline, and fuse in the filter that
//! seeds the next frame. The suite runs at 2 frames a second, slow enough
//! that each frame's filter state reaches ingest and the tracker before
//! the next frame, as the harness does by running its bus to quiescence.

use spacepose_bus::Bus;
use spacepose_e2e::*;
use spacepose_eval::tracking::{EvalConfig, evaluate};
use spacepose_lidar_sim_node::LidarSimConfig;
use spacepose_messages::{Names, PoseEstimate, WireStatus};
use spacepose_scenario::ScenarioKind;
use spacepose_tracker::TrackingMode;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

const FRAMES: u64 = 10;
const SEED: u64 = 7;
/// Agreement required of every component of every published pose.
const TOLERANCE: f64 = 1e-9;

/// The sensor's frame period (s): the integration time `eval tracking`
/// gives the sensor.
fn frame_period_s() -> f64 {
    let sensor = LidarSimConfig {
        scenario: ScenarioKind::Tumbling,
        seed: SEED,
        ..LidarSimConfig::default()
    };
    sensor
        .frame_source()
        .expect("the tumbling scenario builds")
        .scenario()
        .frame_period_s()
}

/// lidar-sim (truth acquisition, as eval), ingest on the target's package,
/// the tracker in deblur mode and the filter; nothing else.
fn descriptor(dir: &std::path::Path) -> std::path::PathBuf {
    let text = format!(
        r#"prefix = "frame-path"
heartbeat_ms = 500
health_timeout_s = 60.0

[zenoh]
listen = []
connect = []

[[service]]
name = "lidar-sim"
kind = "lidar-sim"
[service.config]
target = "deos"
scenario = "tumbling"
seed = {SEED}
frames = {FRAMES}
rate_hz = 2.0
integration_time_s = {period:?}
clutter = false
truth_init = true
exit_at_end = false

[[service]]
name = "ingest"
kind = "ingest"
[service.config]
target = "deos"

[[service]]
name = "tracker"
kind = "tracker"
[service.config]
target = "deos"
[service.config.tracker]
mode = "deblur"

[[service]]
name = "filter"
kind = "filter"
config = {{}}
"#,
        period = frame_period_s(),
    );
    let path = dir.join("frame-path.toml");
    std::fs::write(&path, text).expect("writing the descriptor");
    path
}

/// The suite's published poses, by frame.
fn run_suite() -> BTreeMap<u64, PoseEstimate> {
    require_suite();
    let dir = scratch_dir("frame-path");
    let prefix = unique_prefix("fpath");
    let _down = DownOnDrop(prefix.clone());
    let deploy = descriptor(&dir);
    let names = Names::new(&prefix).expect("a valid prefix");
    let bus = Bus::open(&names, "e2e-frame-path").expect("opening the bus");
    let poses = bus
        .subscriber::<PoseEstimate>(&names.pose())
        .expect("subscribing to the poses");
    let deploy = deploy.to_str().expect("a UTF-8 path");
    let up = spacepose(&["up", deploy, "--prefix", &prefix]);
    assert!(up.status.success(), "{}", text(&up));
    let mut seen = BTreeMap::new();
    let deadline = Instant::now() + Duration::from_secs(120);
    while !seen.contains_key(&(FRAMES - 1)) {
        while let Some(p) = poses.try_recv().expect("receiving poses") {
            seen.entry(p.sequence).or_insert(p);
        }
        assert!(Instant::now() < deadline, "timed out: {:?}", seen.keys());
        std::thread::sleep(Duration::from_millis(10));
    }
    let down = spacepose(&["down", "--prefix", &prefix]);
    assert!(down.status.success(), "{}", text(&down));
    seen
}

#[test]
fn the_suite_and_eval_tracking_publish_the_same_poses() {
    let suite = run_suite();
    let report = evaluate(&EvalConfig {
        frames: Some(FRAMES as usize),
        seed: SEED,
        warmup: 0,
        ..EvalConfig::new(
            ("deos".into(), 1.0),
            ScenarioKind::Tumbling,
            vec![TrackingMode::Deblur],
        )
    })
    .expect("eval tracking runs");
    let eval = &report.modes["deblur"].series;
    assert_eq!(eval.len(), FRAMES as usize);
    let mut worst: f64 = 0.0;
    for r in eval {
        let p = &suite[&(r.frame as u64)];
        assert_eq!(
            WireStatus::from_u8(p.status).unwrap(),
            WireStatus::Tracking,
            "frame {}",
            r.frame
        );
        let pairs = p.q_sensor_target.iter().zip(&r.q_sensor_target);
        let pairs = pairs.chain(p.p_sensor_target.iter().zip(&r.p_sensor_target_m));
        for (a, b) in pairs {
            worst = worst.max((a - b).abs());
        }
        println!(
            "frame {:>2}: suite q {:?} p {:?}\n          eval  q {:?} p {:?}",
            r.frame, p.q_sensor_target, p.p_sensor_target, r.q_sensor_target, r.p_sensor_target_m
        );
    }
    println!("largest difference of a pose component: {worst:e}");
    assert!(worst <= TOLERANCE, "suite and eval differ by {worst:e}");
}
