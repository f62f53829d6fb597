use super::*;
use crate::test_support::Cloud2;
use spacepose_geometry::{TimeBase, TimeMapping, TimeUnit};

fn points() -> Vec<[f32; 4]> {
    vec![
        [1.0, 2.0, 3.0, 10.0],
        [0.1, -0.2, 30.5, 20.0],
        [5.0, 6.0, 7.0, 30.0],
    ]
}

#[test]
fn float64_absolute_t_passes_bit_exact() {
    let t: Vec<Vec<u8>> = [100.5, 100.6, 100.7f64]
        .iter()
        .map(|t| t.to_le_bytes().to_vec())
        .collect();
    let cdr = Cloud2::xyzi(&points(), Some(("t", 8, &t))).to_cdr();
    let parsed = parse(&cdr).unwrap();
    assert_eq!(parsed.frame_id, "lidar");
    let d = decode(&cdr, &InputOptions::default()).unwrap();
    assert_eq!(d.points.len(), 3);
    assert_eq!(d.points[1].x.to_bits(), 0.1f32.to_bits());
    assert_eq!(d.points[1].intensity, 20.0);
    assert_eq!(d.points[2].t, 100.7);
    assert_eq!(d.scan_s, (100.5, 100.7));
    assert_eq!(d.scan_time_source, ScanTimeSource::PointTimes);
    assert!(matches!(d.point_times, PointTimes::Field(ref f) if f.base == TimeBase::Absolute));
}

#[test]
fn livox_offset_time_is_ns_relative_to_the_stamp() {
    let t: Vec<Vec<u8>> = [0u32, 1_000, 50_000_000]
        .iter()
        .map(|t| t.to_le_bytes().to_vec())
        .collect();
    let cdr = Cloud2::xyzi(&points(), Some(("offset_time", 6, &t))).to_cdr();
    let d = decode(&cdr, &InputOptions::default()).unwrap();
    assert_eq!(d.points[0].t, 100.5);
    assert!((d.points[2].t - 100.55).abs() < 1e-9);
    assert!(matches!(d.point_times, PointTimes::Field(ref f) if f.unit == TimeUnit::Ns));
}

#[test]
fn velodyne_float32_time_is_seconds_relative_and_mappings_apply() {
    let t: Vec<Vec<u8>> = [0.0f32, 0.05, 0.1]
        .iter()
        .map(|t| t.to_le_bytes().to_vec())
        .collect();
    let cdr = Cloud2::xyzi(&points(), Some(("time", 7, &t))).to_cdr();
    let d = decode(&cdr, &InputOptions::default()).unwrap();
    assert!((d.points[2].t - 100.6).abs() < 1e-6);
    // The same field read as absolute milliseconds by configuration.
    let options = InputOptions {
        time: TimeMapping {
            field: Some("time".into()),
            unit: Some(TimeUnit::Ms),
            base: Some(TimeBase::Absolute),
        },
        ..InputOptions::default()
    };
    let d = decode(&cdr, &options).unwrap();
    assert!((d.points[2].t - 1e-4).abs() < 1e-9);
}

#[test]
fn no_time_field_derives_times_over_the_scan_period() {
    let cdr = Cloud2::xyzi(&points(), None).to_cdr();
    let options = InputOptions {
        scan_period_s: Some(0.2),
        ..InputOptions::default()
    };
    let d = decode(&cdr, &options).unwrap();
    assert_eq!(d.point_times, PointTimes::Derived);
    assert_eq!(d.scan_time_source, ScanTimeSource::ScanPeriod);
    let t: Vec<f64> = d.points.iter().map(|p| p.t).collect();
    assert_eq!(t[0], 100.5);
    assert!((t[1] - 100.6).abs() < 1e-12 && (t[2] - 100.7).abs() < 1e-12);
}

#[test]
fn sparse_clouds_drop_and_count_non_finite_points() {
    let mut pts = points();
    pts[1][0] = f32::NAN;
    let mut cloud = Cloud2::xyzi(&pts, None);
    let d = decode(&cloud.to_cdr(), &InputOptions::default()).unwrap();
    assert_eq!(
        (d.points.len(), d.dropped_non_finite),
        (3, 0),
        "dense: kept as is"
    );
    cloud.is_dense = false;
    let d = decode(&cloud.to_cdr(), &InputOptions::default()).unwrap();
    assert_eq!((d.points.len(), d.dropped_non_finite), (2, 1));
    assert_eq!(d.points[1].x, 5.0);
}

#[test]
fn organised_clouds_honour_row_padding() {
    let mut cloud = Cloud2::xyzi(&points()[..2], None);
    // Two rows of one point, each row padded to 20 bytes.
    let mut data = cloud.data[..16].to_vec();
    data.extend_from_slice(&[0xAA; 4]);
    data.extend_from_slice(&cloud.data[16..32]);
    cloud.data = data;
    (cloud.height, cloud.width, cloud.row_step) = (2, 1, 20);
    let d = decode(&cloud.to_cdr(), &InputOptions::default()).unwrap();
    assert_eq!(d.points[1].z, 30.5);
}

#[test]
fn unsupported_and_inconsistent_layouts_are_errors() {
    let base = Cloud2::xyzi(&points(), None);
    let err = |c: &Cloud2| decode(&c.to_cdr(), &InputOptions::default()).unwrap_err();

    let mut big = base.clone();
    big.is_bigendian = true;
    assert!(matches!(err(&big), CloudError::BigEndian(_)));
    let mut be_cdr = base.to_cdr();
    be_cdr[1] = 0;
    assert!(matches!(
        decode(&be_cdr, &InputOptions::default()),
        Err(CloudError::BigEndian(_))
    ));

    let full = base.to_cdr();
    for cut in [3, 10, 40, full.len() - 1] {
        assert!(
            matches!(
                decode(&full[..cut], &InputOptions::default()),
                Err(CloudError::Truncated(_))
            ),
            "cut at {cut}"
        );
    }

    let mut outside = base.clone();
    outside.fields[3].1 = 14;
    assert!(matches!(
        err(&outside),
        CloudError::FieldOutsidePoint { .. }
    ));

    let mut unknown = base.clone();
    unknown.fields[2].2 = 9;
    assert!(matches!(
        err(&unknown),
        CloudError::Datatype { datatype: 9, .. }
    ));
    let mut unused_unknown = base.clone();
    unused_unknown.fields.push(("ring", 0, 42, 1));
    assert!(decode(&unused_unknown.to_cdr(), &InputOptions::default()).is_ok());

    let mut int_x = base.clone();
    int_x.fields[0].2 = 5;
    assert!(matches!(err(&int_x), CloudError::FieldType { .. }));

    let mut no_z = base.clone();
    no_z.fields.remove(2);
    assert_eq!(err(&no_z), CloudError::MissingField("z"));

    let mut short = base.clone();
    short.width = 4;
    short.row_step = 64;
    assert!(matches!(err(&short), CloudError::DataTooShort { .. }));

    let mut narrow_row = base.clone();
    narrow_row.row_step = 16;
    assert!(matches!(err(&narrow_row), CloudError::FieldType { .. }));
}

/// Seeded random corruption of valid messages: every outcome is a value
/// (points or an error), never a panic or a runaway allocation.
#[test]
fn corrupted_messages_are_errors_or_points_never_panics() {
    use rand::{RngExt, SeedableRng};
    let t: Vec<Vec<u8>> = [0u32, 1, 2]
        .iter()
        .map(|t| t.to_le_bytes().to_vec())
        .collect();
    let valid = Cloud2::xyzi(&points(), Some(("offset_time", 6, &t))).to_cdr();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(26);
    for _ in 0..5000 {
        let mut m = valid.clone();
        for _ in 0..rng.random_range(1..6) {
            let i = rng.random_range(0..m.len());
            m[i] = rng.random();
        }
        m.truncate(rng.random_range(0..=m.len()));
        if let Ok(d) = decode(&m, &InputOptions::default()) {
            assert!(d.points.len() <= m.len());
        }
    }
    let mut empty_rows = Cloud2::xyzi(&[], None);
    (empty_rows.height, empty_rows.width, empty_rows.row_step) = (u32::MAX, 0, 0);
    let d = decode(&empty_rows.to_cdr(), &InputOptions::default()).unwrap();
    assert!(d.points.is_empty());
}
