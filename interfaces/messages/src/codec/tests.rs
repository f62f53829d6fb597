use super::*;
use crate::*;
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::Point;
use std::fmt::Debug;

pub(super) fn rng() -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(0x5eed_c0dec)
}

fn f(rng: &mut impl Rng) -> f64 {
    rng.random_range(-1e3..1e3)
}

fn arr<const N: usize>(rng: &mut impl Rng) -> [f64; N] {
    std::array::from_fn(|_| f(rng))
}

fn unit_quaternion(rng: &mut impl Rng) -> [f64; 4] {
    let q: [f64; 4] = arr(rng);
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

fn cov<const N: usize>(rng: &mut impl Rng) -> [[f64; N]; N] {
    std::array::from_fn(|_| arr(rng))
}

pub(super) fn pose_estimate(rng: &mut impl Rng) -> PoseEstimate {
    PoseEstimate {
        schema: SCHEMA_VERSION,
        status: rng.random_range(0..4),
        mode: rng.random_range(0..4),
        held_axes: rng.random_range(0..4),
        held_translations: rng.random_range(0..4),
        iterations: rng.random(),
        sequence: rng.random(),
        acquisition_sequence: rng.random(),
        t_s: f(rng),
        instance: Name::new("tracker-a").unwrap(),
        q_sensor_target: arr(rng),
        p_sensor_target: arr(rng),
        covariance: cov(rng),
        cost: f(rng),
        inliers: rng.random(),
        points_used: rng.random(),
        preprocess_ms: f(rng),
        registration_ms: f(rng),
        total_ms: f(rng),
        cloud_published_ns: rng.random(),
        published_ns: rng.random(),
    }
}

pub(super) fn filter_state(rng: &mut impl Rng) -> FilterState {
    FilterState {
        schema: SCHEMA_VERSION,
        initialized: 1,
        sequence: rng.random(),
        t_s: f(rng),
        q_sensor_target: arr(rng),
        p_sensor_target: arr(rng),
        v_sensor: arr(rng),
        w_target: arr(rng),
        w_inertial_sensor: arr(rng),
        attitude_covariance: cov(rng),
        position_covariance: cov(rng),
        published_ns: rng.random(),
    }
}

pub(super) fn acquisition(rng: &mut impl Rng) -> AcquisitionResult {
    AcquisitionResult {
        schema: SCHEMA_VERSION,
        method: rng.random_range(0..3),
        success: 1,
        verification: rng.random_range(0..3),
        sequence: rng.random(),
        t_s: f(rng),
        q_sensor_target: arr(rng),
        p_sensor_target: arr(rng),
        f_conv_m2: f(rng),
        time_ms: f(rng),
        instance: Name::new("init").unwrap(),
    }
}

pub(super) fn truth(rng: &mut impl Rng) -> TruthMsg {
    TruthMsg {
        schema: SCHEMA_VERSION,
        sequence: rng.random(),
        t_s: f(rng),
        q_sensor_target: arr(rng),
        p_sensor_target: arr(rng),
        v_sensor: arr(rng),
        w_target: arr(rng),
    }
}

pub(super) fn health(rng: &mut impl Rng) -> Health {
    Health {
        state: rng.random_range(0..4),
        sequence: rng.random(),
        uptime_s: f(rng),
        counters: Counters {
            frames_in: rng.random(),
            frames_out: rng.random(),
            rejected_non_finite: rng.random(),
            rejected_empty: rng.random(),
            rejected_oversized: rng.random(),
            rejected_wire: rng.random(),
            errors: rng.random(),
            last_frame: rng.random(),
            derived_times: rng.random(),
        },
        published_ns: rng.random(),
        ..Health::new(
            Name::new("tracker").unwrap(),
            Name::new("tracker-b").unwrap(),
            42,
        )
    }
}

pub(super) fn command(rng: &mut impl Rng) -> Command {
    Command {
        mode: rng.random_range(0..4),
        sequence: rng.random(),
        target_instance: Name::new("tracker-a").unwrap(),
        q_sensor_target: unit_quaternion(rng),
        p_sensor_target: arr(rng),
        ..Command::new(CommandKind::Swap, Name::new("ground").unwrap())
    }
}

pub(super) fn cloud(rng: &mut impl Rng, n: usize) -> CloudMsg {
    let points = (0..n)
        .map(|_| {
            Point::new(
                rng.random(),
                rng.random(),
                rng.random(),
                rng.random(),
                f(rng),
            )
        })
        .collect();
    CloudMsg::new(CloudHeader::new(rng.random(), 1.0, 1.1), points)
}

fn round_trip<T: WireMessage + PartialEq + Debug>(msg: &T) -> Vec<u8> {
    let bytes = encode(msg).unwrap();
    assert!(bytes.len() <= T::MAX_WIRE_BYTES);
    assert_eq!(&bytes[..2], b"SP");
    assert_eq!(peek_kind(&bytes), Some(T::KIND));
    let back: T = decode(&bytes).unwrap();
    assert_eq!(&back, msg);
    bytes
}

/// Every rejection the codec promises, on one valid encoding.
fn rejections<T: WireMessage + PartialEq + Debug>(bytes: &[u8]) {
    let mut trailing = bytes.to_vec();
    trailing.push(0);
    assert_eq!(
        decode::<T>(&trailing),
        Err(CodecError::TrailingBytes { extra: 1 })
    );

    let mut version = bytes.to_vec();
    version[2..4].copy_from_slice(&(SCHEMA_VERSION + 1).to_le_bytes());
    assert!(matches!(
        decode::<T>(&version),
        Err(CodecError::UnknownVersion { found, .. }) if found == SCHEMA_VERSION + 1
    ));

    let mut kind = bytes.to_vec();
    kind[4] = T::KIND.wrapping_add(1);
    assert!(matches!(
        decode::<T>(&kind),
        Err(CodecError::WrongKind { .. })
    ));

    let mut magic = bytes.to_vec();
    magic[0] = b'X';
    assert!(matches!(
        decode::<T>(&magic),
        Err(CodecError::BadMagic { .. })
    ));

    for cut in 0..bytes.len() {
        let r = decode::<T>(&bytes[..cut]);
        assert!(r.is_err(), "prefix of {cut}/{} bytes accepted", bytes.len());
        if cut < ENVELOPE_LEN {
            assert_eq!(r, Err(CodecError::Truncated { len: cut }));
        }
    }

    let oversized = vec![0u8; T::MAX_WIRE_BYTES + 1];
    assert!(matches!(
        decode::<T>(&oversized),
        Err(CodecError::Oversized { .. })
    ));
}

fn check<T: WireMessage + PartialEq + Debug>(msg: &T) {
    let bytes = round_trip(msg);
    rejections::<T>(&bytes);
}

#[test]
fn every_message_round_trips_and_rejects_bad_input() {
    let mut rng = rng();
    for _ in 0..20 {
        check(&pose_estimate(&mut rng));
        check(&filter_state(&mut rng));
        check(&acquisition(&mut rng));
        check(&truth(&mut rng));
        check(&health(&mut rng));
        check(&command(&mut rng));
    }
    check(&cloud(&mut rng, 0));
    check(&cloud(&mut rng, 1000));
}

#[test]
fn a_full_size_cloud_fits_and_a_larger_one_is_rejected() {
    let mut rng = rng();
    let max = cloud(&mut rng, MAX_POINTS);
    round_trip(&max);
    let too_big = cloud(&mut rng, MAX_POINTS + 1);
    assert!(matches!(encode(&too_big), Err(CodecError::Invalid(_))));
    let mut lying = cloud(&mut rng, 10);
    lying.header.point_count = 11;
    assert!(matches!(encode(&lying), Err(CodecError::Invalid(_))));
}

#[test]
fn content_is_validated_after_decoding() {
    let mut rng = rng();
    let mut bad_status = pose_estimate(&mut rng);
    bad_status.status = 7;
    assert!(matches!(encode(&bad_status), Err(CodecError::Invalid(_))));
    let mut bad_verification = acquisition(&mut rng);
    bad_verification.verification = 3;
    assert!(matches!(
        encode(&bad_verification),
        Err(CodecError::Invalid(_))
    ));
    let mut bad_held = pose_estimate(&mut rng);
    bad_held.held_axes = 4;
    assert!(matches!(encode(&bad_held), Err(CodecError::Invalid(_))));
    let mut bad_shift = pose_estimate(&mut rng);
    bad_shift.held_translations = 4;
    assert!(matches!(encode(&bad_shift), Err(CodecError::Invalid(_))));

    // Forge a body with a bad code by encoding the raw postcard body ourselves.
    let mut body = postcard::to_allocvec(&bad_status).unwrap();
    let mut bytes = vec![b'S', b'P'];
    bytes.extend_from_slice(&SCHEMA_VERSION.to_le_bytes());
    bytes.push(PoseEstimate::KIND);
    bytes.append(&mut body);
    assert!(matches!(
        decode::<PoseEstimate>(&bytes),
        Err(CodecError::Invalid(_))
    ));

    let mut wrong_schema = command(&mut rng);
    wrong_schema.schema = 0; // e.g. built with Default instead of new()
    let mut bytes = vec![b'S', b'P'];
    bytes.extend_from_slice(&SCHEMA_VERSION.to_le_bytes());
    bytes.push(Command::KIND);
    bytes.extend(postcard::to_allocvec(&wrong_schema).unwrap());
    assert!(matches!(
        decode::<Command>(&bytes),
        Err(CodecError::Invalid(_))
    ));

    let mut bad_name = health(&mut rng);
    bad_name.instance.0[0] = b'/';
    assert!(encode(&bad_name).is_err());
}

/// Decodes `bytes` as every message type; must never panic.
fn decode_all(bytes: &[u8]) -> usize {
    [
        decode::<PoseEstimate>(bytes).is_ok(),
        decode::<FilterState>(bytes).is_ok(),
        decode::<AcquisitionResult>(bytes).is_ok(),
        decode::<TruthMsg>(bytes).is_ok(),
        decode::<Health>(bytes).is_ok(),
        decode::<Command>(bytes).is_ok(),
        decode::<CloudMsg>(bytes).is_ok(),
    ]
    .into_iter()
    .filter(|&ok| ok)
    .count()
}

#[test]
fn seeded_fuzz_never_panics() {
    let mut rng = rng();
    let valid: Vec<Vec<u8>> = vec![
        encode(&pose_estimate(&mut rng)).unwrap(),
        encode(&command(&mut rng)).unwrap(),
        encode(&health(&mut rng)).unwrap(),
        encode(&cloud(&mut rng, 5)).unwrap(),
    ];
    let mut accepted = 0;
    for i in 0..10_000 {
        let bytes = match i % 3 {
            // Pure noise.
            0 => {
                let len = rng.random_range(0..600);
                (0..len).map(|_| rng.random::<u8>()).collect::<Vec<u8>>()
            }
            // A valid envelope followed by noise (reaches postcard).
            1 => {
                let len = rng.random_range(0..600);
                let mut b = vec![b'S', b'P'];
                b.extend_from_slice(&SCHEMA_VERSION.to_le_bytes());
                b.push(rng.random_range(1..8));
                b.extend((0..len).map(|_| rng.random::<u8>()));
                b
            }
            // A valid message with a few flipped bytes, maybe cut or extended.
            _ => {
                let mut b = valid[rng.random_range(0..valid.len())].clone();
                for _ in 0..rng.random_range(1..4) {
                    let at = rng.random_range(0..b.len());
                    b[at] = rng.random();
                }
                match rng.random_range(0..3) {
                    0 => b.truncate(rng.random_range(0..b.len())),
                    1 => b.push(rng.random()),
                    _ => {}
                }
                b
            }
        };
        accepted += decode_all(&bytes);
    }
    // Flipped floats still decode; pure noise almost never does.
    assert!(accepted < 10_000, "accepted {accepted}");
}
