//! Tests of the PLY reader and writer.
use super::*;
use crate::io::test_support::*;

fn finite_cloud() -> Vec<Point> {
    awkward_cloud(300, 4)
}

#[test]
fn ascii_and_binary_round_trip_bit_exactly() {
    let points = finite_cloud();
    for encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
        let bytes = encode_ply(&points, encoding).unwrap();
        assert_bit_equal(&parse_ply(&bytes).unwrap(), &points);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cloud.ply");
    write_ply(&path, &points, PlyEncoding::Ascii).unwrap();
    assert_bit_equal(&read_ply(&path).unwrap(), &points);
}

#[test]
fn non_finite_values_need_binary() {
    let points = [Point::new(f32::NAN, 1.0, 2.0, 0.0, f64::INFINITY)];
    let back = parse_ply(&encode_ply(&points, PlyEncoding::BinaryLittleEndian).unwrap()).unwrap();
    assert!(back[0].x.is_nan() && back[0].t == f64::INFINITY);
    let dir = tempfile::tempdir().unwrap();
    assert!(matches!(
        write_ply(dir.path().join("a.ply"), &points, PlyEncoding::Ascii),
        Err(GeometryError::Unsupported { .. })
    ));
    assert!(
        parse_ply(&encode_ply(&[], PlyEncoding::Ascii).unwrap())
            .unwrap()
            .is_empty()
    );
}

#[test]
fn missing_optional_fields_default_to_zero_and_extras_are_ignored() {
    let text = "ply\nformat ascii 1.0\ncomment from another tool\nelement vertex 2\n\
                property double x\nproperty double y\nproperty double z\n\
                property uchar red\nproperty float nx\nelement face 1\n\
                property list uchar int vertex_indices\nend_header\n\
                1.5 -2 3e2 255 0.5\n0 0 1 0 1\n3 0 1 1\n";
    let points = parse_ply(text.as_bytes()).unwrap();
    assert_eq!(
        points,
        [
            Point::new(1.5, -2.0, 300.0, 0.0, 0.0),
            Point::new(0.0, 0.0, 1.0, 0.0, 0.0)
        ]
    );
}

#[test]
fn float_time_and_integer_intensity_are_read() {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\n\
                      property ushort intensity\nproperty float t\nproperty float x\n\
                      property float y\nproperty float z\nend_header\n"
        .to_vec();
    bytes.extend_from_slice(&4000u16.to_le_bytes());
    for v in [0.25f32, 1.0, 2.0, 3.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    assert_eq!(
        parse_ply(&bytes).unwrap(),
        [Point::new(1.0, 2.0, 3.0, 4000.0, 0.25)]
    );
}

#[test]
fn truncated_files_are_errors() {
    let points = awkward_cloud(20, 3);
    for encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
        let bytes = encode_ply(&points, encoding).unwrap();
        for len in [0, 10, 60, bytes.len() / 2, bytes.len() - 30] {
            assert!(
                parse_ply(&bytes[..len]).is_err(),
                "{encoding:?} truncated to {len} accepted"
            );
        }
    }
}

#[test]
fn garbage_and_hostile_headers_are_errors_not_panics() {
    let garbage: Vec<u8> = (0..2000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    assert!(parse_ply(&garbage).is_err());
    let cases: [&[u8]; 7] = [
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty int y\nproperty int z\nend_header\n1 2 3\n",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 zz\n",
        b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty list uint float x\nproperty float y\nproperty float z\nend_header\n\xff\xff\xff\xff",
        b"ply\nformat ascii 1.0\nelement face 1\nproperty float x\nend_header\n1\n",
    ];
    for case in cases {
        assert!(
            parse_ply(case).is_err(),
            "accepted:\n{}",
            String::from_utf8_lossy(case)
        );
    }
}

#[test]
fn the_timed_reader_picks_a_recognised_time_property() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                property float z\nproperty uint offset_time\nend_header\n1 2 3 0\n4 5 6 1000\n";
    let cloud = parse_ply_timed(text.as_bytes(), &TimeMapping::default()).unwrap();
    assert_eq!(cloud.time.map(|f| f.name), Some("offset_time".to_owned()));
    assert_eq!(cloud.points[1].t, 1000.0);
    let bare = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                property float z\nend_header\n1 2 3\n";
    let cloud = parse_ply_timed(bare.as_bytes(), &TimeMapping::default()).unwrap();
    assert!(cloud.time.is_none() && cloud.points[0].t.is_nan());
    let custom = TimeMapping {
        field: Some("z".into()),
        ..TimeMapping::default()
    };
    assert!(matches!(
        parse_ply_timed(bare.as_bytes(), &custom),
        Err(Issue::Unsupported(_))
    ));
}
