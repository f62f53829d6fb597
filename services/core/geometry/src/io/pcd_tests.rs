use super::*;
use crate::io::test_support::*;
use crate::io::time::{TimeBase, TimeMapping, TimeUnit};

#[test]
fn ascii_and_binary_round_trip_bit_exactly() {
    let points = awkward_cloud(300, 9);
    for encoding in [PcdEncoding::Ascii, PcdEncoding::Binary] {
        let bytes = encode_pcd(&points, encoding).unwrap();
        assert_bit_equal(&parse_pcd(&bytes).unwrap(), &points);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cloud.pcd");
    write_pcd(&path, &points, PcdEncoding::Binary).unwrap();
    assert_bit_equal(&read_pcd(&path).unwrap(), &points);
}

#[test]
fn non_finite_values_and_empty_clouds_round_trip() {
    let points = [Point::new(
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        0.0,
        f64::NAN,
    )];
    for encoding in [PcdEncoding::Ascii, PcdEncoding::Binary] {
        let back = parse_pcd(&encode_pcd(&points, encoding).unwrap()).unwrap();
        assert!(back[0].x.is_nan() && back[0].t.is_nan());
        assert_eq!(back[0].y, f32::INFINITY);
        assert_eq!(back[0].z, f32::NEG_INFINITY);
        assert!(
            parse_pcd(&encode_pcd(&[], encoding).unwrap())
                .unwrap()
                .is_empty()
        );
    }
}

fn header(fields: &str, size: &str, ty: &str, n: usize, data: &str) -> String {
    let count = vec!["1"; fields.split(' ').count()].join(" ");
    format!(
        "VERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {ty}\nCOUNT {count}\n\
         WIDTH {n}\nHEIGHT 1\nPOINTS {n}\nDATA {data}\n"
    )
}

#[test]
fn missing_optional_fields_default_to_zero_and_extra_fields_are_ignored() {
    let text = header("x y z rgb", "4 4 4 4", "F F F U", 2, "ascii") + "1 2 3 77\n-4 5.5 6 0\n";
    let points = parse_pcd(text.as_bytes()).unwrap();
    assert_eq!(
        points,
        [
            Point::new(1.0, 2.0, 3.0, 0.0, 0.0),
            Point::new(-4.0, 5.5, 6.0, 0.0, 0.0)
        ]
    );
}

#[test]
fn double_positions_float_time_integer_intensity_and_padding_are_read() {
    let mut bytes = header(
        "_ intensity x y z t",
        "2 2 8 8 8 4",
        "U U F F F F",
        1,
        "binary",
    )
    .into_bytes();
    bytes.extend_from_slice(&[0xAA, 0xBB]);
    bytes.extend_from_slice(&300u16.to_le_bytes());
    for v in [1.5f64, -2.25, 1e3] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.extend_from_slice(&0.75f32.to_le_bytes());
    let points = parse_pcd(&bytes).unwrap();
    assert_eq!(points, [Point::new(1.5, -2.25, 1000.0, 300.0, 0.75)]);
}

#[test]
fn binary_compressed_files_written_by_pcd_rs_are_read() {
    // The reference compressed file comes from pcd-rs's own writer.
    let mut buf = Cursor::new(Vec::new());
    let schema = [
        ("x", ValueKind::F32, 1),
        ("y", ValueKind::F32, 1),
        ("z", ValueKind::F32, 1),
    ];
    let mut writer: pcd_rs::DynWriter<_> = pcd_rs::WriterInit {
        width: 2,
        height: 1,
        viewpoint: Default::default(),
        data_kind: DataKind::BinaryCompressed,
        schema: Some(schema.into_iter().collect()),
        version: None,
    }
    .build_from_writer(&mut buf)
    .unwrap();
    for v in [1.0f32, 2.0] {
        writer
            .push(&DynRecord(vec![Field::F32(vec![v]); 3]))
            .unwrap();
    }
    writer.finish().unwrap();
    let points = parse_pcd(buf.get_ref()).unwrap();
    assert_eq!(
        points,
        [
            Point::new(1.0, 1.0, 1.0, 0.0, 0.0),
            Point::new(2.0, 2.0, 2.0, 0.0, 0.0)
        ]
    );
    // A lying uncompressed size is rejected before decoding.
    let bytes = buf.into_inner();
    let data_at = bytes
        .windows(22)
        .position(|w| w == b"DATA binary_compressed")
        .unwrap()
        + 23;
    let mut lying = bytes.clone();
    lying[data_at + 4..data_at + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(matches!(parse_pcd(&lying), Err(Issue::Malformed(_))));
}

#[test]
fn truncated_files_are_errors() {
    let points = awkward_cloud(20, 3);
    for encoding in [PcdEncoding::Ascii, PcdEncoding::Binary] {
        let bytes = encode_pcd(&points, encoding).unwrap();
        for len in [0, 10, 60, bytes.len() / 2, bytes.len() - 30] {
            let result = parse_pcd(&bytes[..len]);
            assert!(
                result.is_err(),
                "{encoding:?} truncated to {len} was accepted"
            );
        }
    }
}

#[test]
fn garbage_and_hostile_headers_are_errors_not_panics() {
    let mut rng_bytes: Vec<u8> = (0..2000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    assert!(parse_pcd(&rng_bytes).is_err());
    let valid = encode_pcd(&awkward_cloud(5, 1), PcdEncoding::Binary).unwrap();
    rng_bytes.splice(0..0, valid[..valid.len() - 40].iter().copied());
    assert!(parse_pcd(&rng_bytes[..valid.len() - 10]).is_err());
    let cases = [
        header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 2\n",
        header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 2 abc\n",
        header("x y z", "4 4 4", "F F F", 2, "ascii") + "1 2 3\n",
        header("x y", "4 4", "F F", 1, "ascii") + "1 2\n",
        header("x y z", "4 4 4", "I I I", 1, "ascii") + "1 2 3\n",
        header("x y z", "4 4 4", "F F F", 1, "binary_compressed") + "\x01\x00",
        header("x y z", "4 4 4", "F F F", usize::MAX / 2, "binary") + "abcdefghijkl",
        "VERSION 0.7\nFIELDS x y z _\nSIZE 4 4 4 8\nTYPE F F F U\nCOUNT 1 1 1 99999999999\n\
         WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\n"
            .to_string(),
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n"
            .to_string(),
        "VERSION 0.7\nFIELDS x y z\n".to_string(),
    ];
    for case in &cases {
        assert!(parse_pcd(case.as_bytes()).is_err(), "accepted:\n{case}");
    }
}

#[test]
fn the_timed_reader_reports_the_field_or_its_absence() {
    let dir = tempfile::tempdir().unwrap();
    let points = awkward_cloud(20, 4);
    let path = dir.path().join("own.pcd");
    write_pcd(&path, &points, PcdEncoding::Binary).unwrap();
    let own = crate::io::read_cloud_timed(&path, &TimeMapping::default()).unwrap();
    assert_bit_equal(&own.points, &points);
    assert_eq!(own.time.map(|f| f.name), Some("t".to_owned()));

    let bare = dir.path().join("bare.pcd");
    let text = header("x y z", "4 4 4", "F F F", 2, "ascii") + "1 2 3\n4 5 6\n";
    std::fs::write(&bare, text).unwrap();
    let cloud = crate::io::read_cloud_timed(&bare, &TimeMapping::default()).unwrap();
    assert!(cloud.time.is_none());
    assert!(
        cloud.points.iter().all(|p| p.t.is_nan()),
        "never a silent t = 0"
    );
}

#[test]
fn livox_offset_time_is_an_integer_in_nanoseconds() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("livox.pcd");
    let text =
        header("x y z offset_time", "4 4 4 4", "F F F U", 2, "ascii") + "1 2 3 0\n4 5 6 2500000\n";
    std::fs::write(&path, text).unwrap();
    let cloud = crate::io::read_cloud_timed(&path, &TimeMapping::default()).unwrap();
    let field = cloud.time.unwrap();
    assert_eq!(
        (field.name.as_str(), field.unit, field.base),
        ("offset_time", TimeUnit::Ns, TimeBase::Relative)
    );
    assert_eq!(cloud.points[1].t, 2_500_000.0 * 1e-9);
    // The plain reader still refuses an integer `t`.
    let int_t = header("x y z t", "4 4 4 4", "F F F U", 1, "ascii") + "1 2 3 7\n";
    assert!(matches!(
        parse_pcd(int_t.as_bytes()),
        Err(Issue::Unsupported(_))
    ));
    let timed = parse_pcd_timed(int_t.as_bytes(), &TimeMapping::default()).unwrap();
    assert_eq!(timed.points[0].t, 7.0);
}
