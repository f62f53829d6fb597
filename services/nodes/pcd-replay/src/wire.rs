//! A replayed frame on the wire.

use spacepose_input::InputFrame;
use spacepose_messages::CloudHeader;

/// The raw-cloud header of a replayed frame: `sequence` counts the frames
/// published (across passes), not the file indices.
pub fn cloud_header(sequence: u64, frame: &InputFrame, sensor_id: u16) -> CloudHeader {
    let mut header = CloudHeader::new(sequence, frame.scan_start_s, frame.scan_end_s);
    header.sensor_id = sensor_id;
    header
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_input::{PointTimes, ScanTimeSource};

    #[test]
    fn the_header_takes_the_scan_times_and_the_sensor() {
        let frame = InputFrame {
            index: 42,
            origin: "frame_000042.pcd".into(),
            frame_id: String::new(),
            points: Vec::new(),
            scan_start_s: 1.28,
            scan_end_s: 2.0,
            scan_time_source: ScanTimeSource::TruthCsv,
            point_times: PointTimes::Derived,
            dropped_non_finite: 0,
        };
        let h = cloud_header(3, &frame, 7);
        assert_eq!(
            (h.sequence, h.scan_start_s, h.scan_end_s, h.sensor_id),
            (3, 1.28, 2.0, 7)
        );
        assert_eq!(h.point_count, 0);
    }
}
