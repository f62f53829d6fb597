use super::*;
use crate::test_support::{Cloud2, spacepose_cloud};
use crate::{Recording, ScanTimeSource, open};
use mcap::records::MessageHeader;
use std::io::Cursor;

/// One message to write: topic, schema name, message encoding, log time, data.
type Entry<'a> = (&'a str, &'a str, &'a str, u64, Vec<u8>);

fn write_mcap(path: &Path, entries: &[Entry]) {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let mut ids: BTreeMap<&str, u16> = BTreeMap::new();
    for (k, (topic, schema, encoding, log_time, data)) in entries.iter().enumerate() {
        let id = match ids.get(topic) {
            Some(&id) => id,
            None => {
                let schema_encoding = if *encoding == "cdr" {
                    "ros2msg"
                } else {
                    "jsonschema"
                };
                let sid = w.add_schema(schema, schema_encoding, b"").unwrap();
                let id = w
                    .add_channel(sid, topic, encoding, &BTreeMap::new())
                    .unwrap();
                ids.insert(topic, id);
                id
            }
        };
        let header = MessageHeader {
            channel_id: id,
            sequence: k as u32,
            log_time: *log_time,
            publish_time: *log_time,
        };
        w.write_to_known_channel(&header, data).unwrap();
    }
    w.finish().unwrap();
    std::fs::write(path, w.into_inner().into_inner()).unwrap();
}

fn ros_cloud(x: f32) -> Vec<u8> {
    Cloud2::xyzi(&[[x, 0.0, 10.0, 1.0], [x, 1.0, 10.0, 1.0]], None).to_cdr()
}

const ROS: &str = pointcloud2::SCHEMA_NAME;
const FOX: &str = foxglove_cloud::SCHEMA_NAME;

#[test]
fn ros_clouds_come_in_order_and_a_bad_message_does_not_stop_the_reading() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("run.mcap");
    let mut bad = ros_cloud(9.0);
    bad[1] = 0; // big-endian CDR
    write_mcap(
        &path,
        &[
            ("/points", ROS, "cdr", 10, ros_cloud(1.0)),
            ("/imu", "sensor_msgs/msg/Imu", "cdr", 11, vec![0, 1, 0, 0]),
            ("/points", ROS, "cdr", 20, bad),
            ("/points", ROS, "cdr", 30, ros_cloud(3.0)),
        ],
    );
    let mut rec = open(&path, &InputOptions::default()).unwrap();
    assert_eq!(rec.len_hint(), Some(3));
    assert!(rec.describe().contains("/points"), "{}", rec.describe());
    let frames: Vec<_> = rec.frames().collect();
    assert_eq!(frames.len(), 3);
    let first = frames[0].as_ref().unwrap();
    assert_eq!((first.index, first.points[0].x), (0, 1.0));
    assert!(first.times_derived());
    assert!(matches!(
        frames[1],
        Err(InputError::Message {
            log_time_ns: 20,
            source: CloudError::BigEndian(_),
            ..
        })
    ));
    assert_eq!(frames[2].as_ref().unwrap().index, 2);
}

#[test]
fn spacepose_clouds_pair_with_their_headers_in_either_order() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("run.mcap");
    let header = |seq: u64, start: f64| {
        format!(
            r#"{{"sequence":{seq},"scan_start_s":{start},"scan_end_s":{},"sensor_id":0}}"#,
            start + 0.4
        )
        .into_bytes()
    };
    let cloud = |t: f64| spacepose_cloud(&[[1.0, 2.0, 3.0, 0.0, t], [1.0, 2.0, 4.0, 0.0, t + 0.1]]);
    let h = "/spacepose/raw_cloud/header";
    write_mcap(
        &path,
        &[
            ("/spacepose/raw_cloud", FOX, "protobuf", 100, cloud(5.1)),
            (h, "spacepose.CloudHeader", "json", 100, header(41, 5.0)),
            (h, "spacepose.CloudHeader", "json", 200, header(42, 6.0)),
            ("/spacepose/raw_cloud", FOX, "protobuf", 200, cloud(6.1)),
            ("/spacepose/raw_cloud", FOX, "protobuf", 300, cloud(7.1)),
        ],
    );
    let mut rec = open(&path, &InputOptions::default()).unwrap();
    let Recording::Mcap(source) = &rec else {
        panic!("not an MCAP recording")
    };
    assert!(source.has_spacepose_headers());
    let frames: Vec<InputFrame> = rec.frames().map(Result::unwrap).collect();
    let got: Vec<_> = frames
        .iter()
        .map(|f| (f.index, f.scan_start_s, f.scan_time_source))
        .collect();
    assert_eq!(
        got,
        [
            (41, 5.0, ScanTimeSource::SpaceposeHeader),
            (42, 6.0, ScanTimeSource::SpaceposeHeader),
            (2, 7.1, ScanTimeSource::PointTimes),
        ]
    );
    assert_eq!(frames[1].points[1].t, 6.1 + 0.1);
    // A cursor reads the same frames, and a new one starts again.
    for _ in 0..2 {
        let mut cursor = rec.cursor();
        let again: Vec<_> = std::iter::from_fn(|| rec.next_frame(&mut cursor))
            .map(|f| f.unwrap().index)
            .collect();
        assert_eq!(again, [41, 42, 2]);
    }
}

#[test]
fn the_topic_is_chosen_or_the_choices_are_listed() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("two.mcap");
    write_mcap(
        &path,
        &[
            ("/a", ROS, "cdr", 1, ros_cloud(1.0)),
            (
                "/b",
                FOX,
                "protobuf",
                2,
                spacepose_cloud(&[[0.0, 0.0, 1.0, 0.0, 1.0]]),
            ),
            ("/imu", "sensor_msgs/msg/Imu", "cdr", 3, vec![]),
        ],
    );
    let err = open(&path, &InputOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("/a (sensor_msgs/msg/PointCloud2)")
            && err.contains("/b (foxglove.PointCloud)"),
        "{err}"
    );
    let with = |topic: &str| InputOptions {
        topic: Some(topic.into()),
        ..InputOptions::default()
    };
    let mut rec = open(&path, &with("/b")).unwrap();
    assert_eq!(rec.frames().count(), 1);
    assert!(
        open(&path, &with("/imu"))
            .unwrap_err()
            .to_string()
            .contains("not point clouds")
    );
    assert!(
        open(&path, &with("/c"))
            .unwrap_err()
            .to_string()
            .contains("no topic /c")
    );
}

#[test]
fn truncated_and_garbage_files_are_errors_not_panics() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("run.mcap");
    let entries: Vec<Entry> = (0..20)
        .map(|k| ("/points", ROS, "cdr", k, ros_cloud(k as f32)))
        .collect();
    write_mcap(&path, &entries);
    let full = std::fs::read(&path).unwrap();
    for cut in [9, 100, full.len() / 2, full.len() - 30] {
        let cut_path = tmp.path().join(format!("cut{cut}.mcap"));
        std::fs::write(&cut_path, &full[..cut]).unwrap();
        if let Ok(mut rec) = open(&cut_path, &InputOptions::default()) {
            let results: Vec<_> = rec.frames().collect();
            // The frames before the cut, then one error for the cut; a cut
            // in the summary section leaves every message readable.
            let all_read = results.len() == 20 && results.iter().all(Result::is_ok);
            let cut_reported = results.last().is_some_and(Result::is_err);
            assert!(
                results.len() <= 21 && (all_read || cut_reported),
                "cut at {cut}"
            );
        }
    }
    let garbage = tmp.path().join("garbage.mcap");
    std::fs::write(&garbage, b"\x89MCAP0\r\nnot really").unwrap();
    assert!(open(&garbage, &InputOptions::default()).is_err());
    let text = tmp.path().join("notes.txt");
    std::fs::write(&text, b"hello").unwrap();
    assert!(matches!(
        open(&text, &InputOptions::default()),
        Err(InputError::UnknownFormat(_))
    ));
}

#[test]
fn a_bag_reads_its_split_files_in_order() {
    let tmp = tempfile::tempdir().unwrap();
    let bag = tmp.path().join("bag");
    std::fs::create_dir(&bag).unwrap();
    std::fs::write(bag.join("metadata.yaml"), "rosbag2_bagfile_information:\n").unwrap();
    for (k, name) in [(10u64, "bag_10.mcap"), (2, "bag_2.mcap"), (1, "bag_1.mcap")] {
        write_mcap(
            &bag.join(name),
            &[("/points", ROS, "cdr", k, ros_cloud(k as f32))],
        );
    }
    let mut rec = open(&bag, &InputOptions::default()).unwrap();
    let xs: Vec<f32> = rec.frames().map(|f| f.unwrap().points[0].x).collect();
    assert_eq!(xs, [1.0, 2.0, 10.0]);
    let mut cursor = rec.cursor();
    let by_cursor: Vec<f32> = std::iter::from_fn(|| rec.next_frame(&mut cursor))
        .map(|f| f.unwrap().points[0].x)
        .collect();
    assert_eq!(by_cursor, xs);
    assert!(rec.next_frame(&mut cursor).is_none());
    let empty = tmp.path().join("sqlite");
    std::fs::create_dir(&empty).unwrap();
    std::fs::write(empty.join("metadata.yaml"), "x").unwrap();
    assert!(
        open(&empty, &InputOptions::default())
            .unwrap_err()
            .to_string()
            .contains("sqlite3")
    );
}

/// Seeded random corruption of a valid file: errors, never a panic.
#[test]
fn corrupted_files_are_errors_never_panics() {
    use rand::{RngExt, SeedableRng};
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("run.mcap");
    let entries: Vec<Entry> = (0..5)
        .map(|k| ("/points", ROS, "cdr", k, ros_cloud(k as f32)))
        .collect();
    write_mcap(&path, &entries);
    let valid = std::fs::read(&path).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(26);
    let bad = tmp.path().join("bad.mcap");
    for _ in 0..300 {
        let mut m = valid.clone();
        for _ in 0..rng.random_range(1..4) {
            let i = rng.random_range(8..m.len());
            m[i] = rng.random();
        }
        std::fs::write(&bad, &m).unwrap();
        if let Ok(mut rec) = open(&bad, &InputOptions::default()) {
            assert!(rec.frames().count() <= 6);
        }
    }
}
