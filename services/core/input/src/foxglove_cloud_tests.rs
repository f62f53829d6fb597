use super::*;
use crate::test_support::spacepose_cloud;
use foxglove::Encode;
use spacepose_geometry::PointTimes;

const POINTS: [[f64; 5]; 2] = [[1.0, 2.0, 3.0, 4.0, 7.3], [0.1, 0.2, 0.3, 0.0, 7.35]];

#[test]
fn spacepose_clouds_read_back_exactly_with_their_header() {
    let bytes = spacepose_cloud(&POINTS);
    let header =
        parse_header(br#"{"sequence":12,"scan_start_s":7.25,"scan_end_s":7.4,"sensor_id":1}"#)
            .unwrap();
    let d = decode(&bytes, Some(&header), &InputOptions::default()).unwrap();
    assert_eq!(d.scan_s, (7.25, 7.4));
    assert_eq!(d.scan_time_source, ScanTimeSource::SpaceposeHeader);
    assert_eq!(d.points[1].t, 7.35);
    assert_eq!(d.points[1].x.to_bits(), 0.1f32.to_bits());
    assert!(matches!(d.point_times, PointTimes::Field(ref f) if f.name == "t"));
    // Without the header: the span of the point times.
    let d = decode(&bytes, None, &InputOptions::default()).unwrap();
    assert_eq!(
        (d.scan_s, d.scan_time_source),
        ((7.3, 7.35), ScanTimeSource::PointTimes)
    );
}

#[test]
fn other_layouts_and_types_are_read_and_bad_ones_refused() {
    // uint16 coordinates are refused; int8 intensity is read.
    let mut cloud = PointCloud::decode(spacepose_cloud(&POINTS).as_slice()).unwrap();
    cloud.fields[3].r#type = 2;
    let mut ok = Vec::new();
    cloud.encode(&mut ok).unwrap();
    let d = decode(&ok, None, &InputOptions::default()).unwrap();
    assert_eq!(d.points[0].intensity, 0.0, "low byte of 4.0f32 as int8");
    cloud.fields[0].r#type = 3;
    let mut bad = Vec::new();
    cloud.encode(&mut bad).unwrap();
    assert!(matches!(
        decode(&bad, None, &InputOptions::default()),
        Err(CloudError::FieldType { .. })
    ));
    cloud.fields[0].r#type = 0;
    let mut unknown = Vec::new();
    cloud.encode(&mut unknown).unwrap();
    assert!(matches!(
        decode(&unknown, None, &InputOptions::default()),
        Err(CloudError::Datatype { datatype: 0, .. })
    ));
}

#[test]
fn ragged_data_garbage_and_bad_headers_are_errors() {
    let mut cloud = PointCloud::decode(spacepose_cloud(&POINTS).as_slice()).unwrap();
    cloud.point_stride = 20;
    let mut ragged = Vec::new();
    cloud.encode(&mut ragged).unwrap();
    assert!(matches!(
        decode(&ragged, None, &InputOptions::default()),
        Err(CloudError::DataTooShort { .. })
    ));
    cloud.point_stride = 0;
    let mut zero = Vec::new();
    cloud.encode(&mut zero).unwrap();
    assert!(decode(&zero, None, &InputOptions::default()).is_err());
    assert!(matches!(
        decode(&[0xff, 0xff, 0xff], None, &InputOptions::default()),
        Err(CloudError::Decode(_))
    ));
    assert!(parse_header(b"{\"sequence\":1}").is_err());
    assert!(
        parse_header(br#"{"sequence":1,"scan_start_s":2.0,"scan_end_s":1.0,"sensor_id":0}"#)
            .is_err()
    );
}

#[test]
fn no_time_field_derives_from_the_timestamp() {
    let mut cloud = PointCloud::decode(spacepose_cloud(&POINTS).as_slice()).unwrap();
    cloud.fields.pop();
    let mut bytes = Vec::new();
    cloud.encode(&mut bytes).unwrap();
    let d = decode(&bytes, None, &InputOptions::default()).unwrap();
    assert_eq!(d.point_times, PointTimes::Derived);
    assert_eq!(d.points[0].t, 7.25);
    assert!((d.points[1].t - 7.35).abs() < 1e-12);
}
