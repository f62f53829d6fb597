use super::*;

fn fields(list: &[(&'static str, bool)]) -> Vec<(&'static str, bool)> {
    list.to_vec()
}

#[test]
fn recognised_names_get_their_default_unit_and_base() {
    let m = TimeMapping::default();
    let pick = |list: &[(&'static str, bool)]| m.resolve(fields(list)).unwrap().unwrap();
    let spacepose = pick(&[("x", false), ("t", false), ("time", false)]);
    assert_eq!(
        (spacepose.name.as_str(), spacepose.unit, spacepose.base),
        ("t", TimeUnit::S, TimeBase::Absolute)
    );
    let ouster = pick(&[("t", true)]);
    assert_eq!(
        (ouster.unit, ouster.base),
        (TimeUnit::Ns, TimeBase::Relative)
    );
    let velodyne = pick(&[("time", false)]);
    assert_eq!(
        (velodyne.unit, velodyne.base),
        (TimeUnit::S, TimeBase::Relative)
    );
    let hesai = pick(&[("timestamp", false)]);
    assert_eq!((hesai.unit, hesai.base), (TimeUnit::S, TimeBase::Absolute));
    let livox = pick(&[("offset_time", true)]);
    assert_eq!((livox.unit, livox.base), (TimeUnit::Ns, TimeBase::Relative));
    assert_eq!(m.resolve(fields(&[("x", false), ("ring", true)])), Ok(None));
}

#[test]
fn a_configured_mapping_overrides_and_a_missing_field_is_an_error() {
    let m = TimeMapping {
        field: Some("stamp_us".into()),
        unit: Some(TimeUnit::Us),
        base: Some(TimeBase::Relative),
    };
    let f = m.resolve(fields(&[("stamp_us", true)])).unwrap().unwrap();
    assert_eq!((f.unit, f.base), (TimeUnit::Us, TimeBase::Relative));
    let e = m.resolve(fields(&[("t", false)])).unwrap_err();
    assert!(e.contains("stamp_us") && e.contains("\"t\""), "{e}");
    assert!(m.validate().is_ok());
    let empty = TimeMapping {
        field: Some(" ".into()),
        ..TimeMapping::default()
    };
    assert!(empty.validate().is_err());
}

#[test]
fn derived_times_are_linear_in_point_order_and_flagged() {
    let cloud = TimedCloud {
        points: vec![Point::default(); 5],
        time: None,
    };
    let (points, source) = cloud.into_absolute(99.0, (10.0, 10.4));
    assert_eq!(source, PointTimes::Derived);
    let t: Vec<f64> = points.iter().map(|p| p.t).collect();
    assert_eq!(t[0], 10.0);
    assert_eq!(t[4], 10.4);
    assert!((t[2] - 10.2).abs() < 1e-12);
    let mut one = [Point::default()];
    derive_linear_times(&mut one, 3.0, 4.0);
    assert_eq!(one[0].t, 3.0);
}

#[test]
fn relative_field_times_get_the_reference_added() {
    let field = TimeField {
        name: "offset_time".into(),
        unit: TimeUnit::Ns,
        base: TimeBase::Relative,
    };
    let cloud = TimedCloud {
        points: vec![Point::new(0.0, 0.0, 1.0, 0.0, 0.25)],
        time: Some(field.clone()),
    };
    let (points, source) = cloud.into_absolute(100.0, (0.0, 0.0));
    assert_eq!(points[0].t, 100.25);
    assert_eq!(source, PointTimes::Field(field));
}
