//! The `spacepose-init` binary as a real process, fed and read through the
//! bus.
#![allow(clippy::unwrap_used)] // tests may unwrap (clippy.toml only covers #[test] fns)

use spacepose_bus::{Bus, Subscriber};
use spacepose_cnn::{DatasetConfig, Generator};
use spacepose_geometry::Point;
use spacepose_messages::{
    AcquisitionMethod, AcquisitionResult, CloudHeader, Health, MAX_POINTS, Names, PoseEstimate,
    ServiceState, WireStatus,
};
use spacepose_model::Target;
use spacepose_runtime::testing::{self, ChildGuard};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::Duration;

/// Polls until `f` gives a value (60 s at most: the chain is built first).
fn wait_for<T>(what: &str, f: impl FnMut() -> Option<T>) -> T {
    testing::wait_for(what, Duration::from_secs(60), f)
}

/// The latest health message once `pred` holds for it.
fn health_until(sub: &Subscriber<Health>, what: &str, pred: impl Fn(&Health) -> bool) -> Health {
    wait_for(what, || {
        let mut found = None;
        while let Some(h) = sub.try_recv().unwrap() {
            if pred(&h) {
                found = Some(h);
            }
        }
        found
    })
}

fn repo_root() -> PathBuf {
    Path::new(
        &std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned()),
    )
    .join("../../..")
}

/// A config file: the CNN (the default, relative `model_dir` unless given)
/// then template matching, as `instance`.
fn config_file(dir: &Path, instance: &str, model_dir: Option<&str>) -> PathBuf {
    let mut text =
        format!("instance = \"{instance}\"\nmethods = [\"cnn\", \"template-matching\"]\n");
    if let Some(m) = model_dir {
        text.push_str(&format!("[cnn]\nmodel_dir = \"{m}\"\n"));
    }
    let path = dir.join("init.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// `spacepose-init` on `prefix` with `config`, to start in `cwd`.
fn command(prefix: &str, config: &Path, cwd: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_spacepose-init"));
    c.args(["--prefix", prefix, "--heartbeat-ms", "20", "--config"])
        .arg(config)
        .current_dir(cwd);
    c
}

fn spawn(prefix: &str, config: &Path, cwd: &Path) -> ChildGuard {
    ChildGuard(command(prefix, config, cwd).spawn().unwrap())
}

fn terminate(guard: &mut ChildGuard, health: &Subscriber<Health>) {
    let pid = guard.0.id().to_string();
    let kill = Command::new("kill").args(["-TERM", &pid]).status().unwrap();
    assert!(kill.success());
    let status = wait_for("the exit", || guard.0.try_wait().unwrap());
    assert!(status.success(), "{status:?}");
    health_until(health, "the stopping heartbeat", |h| {
        h.state == ServiceState::Stopping as u8
    });
}

/// Started from the repository root with the default model directory: the
/// config's instance name, a CNN acquisition at start, the counters, and a
/// clean stop.
#[test]
fn init_acquires_at_start_counts_and_stops_cleanly() {
    let prefix = testing::unique_prefix("init");
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "init-test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let results = bus
        .subscriber::<AcquisitionResult>(&names.acquisition())
        .unwrap();
    let clouds = bus.cloud_publisher(&names.cloud(), MAX_POINTS).unwrap();
    let poses = bus.publisher::<PoseEstimate>(&names.pose()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut guard = spawn(
        &prefix,
        &config_file(dir.path(), "init-a", None),
        &repo_root(),
    );
    health_until(&health, "the first heartbeat", |h| {
        h.state == ServiceState::Running as u8
            && (h.service.as_str(), h.instance.as_str()) == ("init", "init-a")
    });

    // A malformed estimate: refused and counted.
    let mut bad = PoseEstimate::new();
    bad.status = 9;
    poses.send(&bad).unwrap();
    // A deos frame with one non-finite point: acquired by the CNN.
    let deos = Arc::new(Target::builtin("deos").unwrap());
    let dataset = DatasetConfig {
        seed: 1003,
        count: 3,
        image_size: 64,
        roll_step_deg: 20.0,
        min_points: spacepose_cnn::DEFAULT_MIN_POINTS,
    };
    let frame = Generator::new(deos, dataset).unwrap().frame(1).unwrap();
    let mut points = frame.points.clone();
    points.push(Point::new(f32::NAN, 0.0, 15.0, 1.0, 0.0));
    clouds.send(CloudHeader::new(7, 7.0, 7.5), &points).unwrap();
    // The (uninitialised) tracker says it does not track: acquire. Until a
    // tracker answers, init only listens.
    let mut lost = PoseEstimate::new();
    lost.sequence = 7;
    lost.status = WireStatus::Lost as u8;
    poses.send(&lost).unwrap();
    let r = wait_for("the acquisition result", || results.try_recv().unwrap());
    assert_eq!((r.sequence, r.t_s, r.success), (7, 7.5, 1));
    assert_eq!(r.method, AcquisitionMethod::Cnn as u8);
    assert_eq!(r.instance.as_str(), "init-a");
    let (_, dist_m) = r.pose().unwrap().error_to(&frame.truth.t_sensor_target);
    assert!(dist_m < 0.15, "{dist_m} m off");

    let h = health_until(&health, "the counters", |h| h.counters.frames_out == 1);
    assert_eq!((h.counters.frames_in, h.counters.last_frame), (1, 7));
    assert_eq!(
        (h.counters.rejected_non_finite, h.counters.rejected_wire),
        (1, 1)
    );
    assert_eq!((h.counters.rejected_empty, h.counters.errors), (0, 0));
    assert!(
        results.try_recv().unwrap().is_none(),
        "one result per attempt"
    );
    terminate(&mut guard, &health);
}

/// Started elsewhere, the default model directory is found in the source
/// tree; a model directory found nowhere stops the start, naming it.
#[test]
fn the_model_is_found_from_another_directory_and_a_missing_one_is_an_error() {
    let prefix = testing::unique_prefix("initcwd");
    let names = Names::new(&prefix).unwrap();
    let bus = Bus::open(&names, "init-cwd-test").unwrap();
    let health = bus.subscriber::<Health>(&names.health()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut guard = spawn(&prefix, &config_file(dir.path(), "init", None), dir.path());
    health_until(&health, "the first heartbeat", |h| {
        h.state == ServiceState::Running as u8
    });
    terminate(&mut guard, &health);

    let absent = "services/core/cnn/models/absent";
    let config = config_file(dir.path(), "init", Some(absent));
    let out = command(&prefix, &config, dir.path())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(absent), "{stderr}");
}
