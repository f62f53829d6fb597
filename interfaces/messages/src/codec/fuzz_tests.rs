//! Seeded fuzzing of [`decode`] for every message kind: 10^4 mutations of
//! valid encodings per kind. Never a panic; every mutation that cannot be a
//! valid message (truncated, trailing bytes, wrong magic, version, kind or
//! schema field, oversized, random bytes, a non-finite command) is rejected;
//! bit flips and random bodies behind a valid envelope are either rejected
//! or decode to a message that passes validation again.

use super::tests::{acquisition, cloud, command, filter_state, health, pose_estimate, rng, truth};
use super::*;
use crate::*;
use rand::{Rng, RngExt};
use std::fmt::Debug;

const CASES_PER_KIND: usize = 10_000;

/// Outcome counts of one kind.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct Tally {
    /// Mutations that cannot be valid.
    must_reject: usize,
    /// ... of which rejected (must equal `must_reject`).
    rejected: usize,
    /// Bit flips and random bodies (may stay valid).
    maybe: usize,
    /// ... of which rejected.
    maybe_rejected: usize,
}

fn frame(kind: u8, version: u16, body: &[u8]) -> Vec<u8> {
    let mut b = MAGIC.to_vec();
    b.extend_from_slice(&version.to_le_bytes());
    b.push(kind);
    b.extend_from_slice(body);
    b
}

fn noise(rng: &mut impl Rng, len: usize) -> Vec<u8> {
    (0..len).map(|_| rng.random::<u8>()).collect()
}

/// One mutation of `valid`; `true` when it can never be a valid message.
fn mutate<T: WireMessage>(
    rng: &mut impl Rng,
    valid: &[u8],
    oversized: &mut [u8],
) -> (Vec<u8>, bool) {
    let len = valid.len();
    match rng.random_range(0..10) {
        0 => (valid[..rng.random_range(0..len)].to_vec(), true),
        1 => {
            let mut b = valid.to_vec();
            let extra = rng.random_range(1..9);
            b.extend(noise(rng, extra));
            (b, true)
        }
        2 => {
            let mut b = valid.to_vec();
            let v = loop {
                let v: u16 = rng.random();
                if v != SCHEMA_VERSION {
                    break v;
                }
            };
            b[2..4].copy_from_slice(&v.to_le_bytes());
            (b, true)
        }
        3 => {
            let mut b = valid.to_vec();
            b[4] = loop {
                let k: u8 = rng.random();
                if k != T::KIND {
                    break k;
                }
            };
            (b, true)
        }
        4 => {
            let mut b = valid.to_vec();
            let at = rng.random_range(0..2);
            b[at] ^= rng.random_range(1..=255u8);
            (b, true)
        }
        5 => {
            // Oversized: the length alone refuses it (one shared buffer, so a
            // 4.8 MB cloud bound costs one allocation, not one per case).
            let at = rng.random_range(0..oversized.len());
            oversized[at] = rng.random();
            let cut = oversized.len() - rng.random_range(0..16);
            (oversized[..cut].to_vec(), true)
        }
        6 => {
            let n = rng.random_range(0..600);
            (noise(rng, n), true)
        }
        7 => {
            // The schema field (first field of every body: a one-byte varint
            // right after the envelope) differs from the envelope.
            let mut b = valid.to_vec();
            b[ENVELOPE_LEN] = loop {
                let s = rng.random_range(0..0x80u8);
                if u16::from(s) != SCHEMA_VERSION {
                    break s;
                }
            };
            (b, true)
        }
        8 => {
            let n = rng.random_range(0..600);
            (frame(T::KIND, SCHEMA_VERSION, &noise(rng, n)), false)
        }
        _ => {
            let mut b = valid.to_vec();
            for _ in 0..rng.random_range(1..9) {
                let at = rng.random_range(0..len);
                b[at] ^= 1 << rng.random_range(0..8);
            }
            (b, false)
        }
    }
}

fn fuzz<T: WireMessage + Debug>(valid: &[Vec<u8>], extra_must_reject: &[Vec<u8>]) -> Tally {
    let mut rng = rng();
    let mut oversized = vec![0u8; T::MAX_WIRE_BYTES + 16];
    let mut t = Tally::default();
    let check = |bytes: &[u8], must: bool, t: &mut Tally| {
        let r = decode::<T>(bytes);
        if let Ok(msg) = &r {
            // What the codec lets through is a valid message.
            assert!(msg.validate().is_ok(), "accepted an invalid {msg:?}");
            assert!(!must, "accepted a mutation that cannot be valid: {msg:?}");
        }
        if must {
            t.must_reject += 1;
            t.rejected += usize::from(r.is_err());
        } else {
            t.maybe += 1;
            t.maybe_rejected += usize::from(r.is_err());
        }
    };
    for bytes in extra_must_reject {
        check(bytes, true, &mut t);
    }
    for i in 0..CASES_PER_KIND - extra_must_reject.len() {
        let base = &valid[i % valid.len()];
        let (bytes, must) = mutate::<T>(&mut rng, base, &mut oversized);
        check(&bytes, must, &mut t);
    }
    assert_eq!(t.rejected, t.must_reject);
    assert_eq!(t.must_reject + t.maybe, CASES_PER_KIND);
    t
}

fn encoded<T: WireMessage>(msgs: impl IntoIterator<Item = T>) -> Vec<Vec<u8>> {
    msgs.into_iter().map(|m| encode(&m).unwrap()).collect()
}

/// Commands with a NaN or infinite pose component, or a non-unit quaternion,
/// encoded without the encoder's validation.
fn bad_commands(rng: &mut impl Rng, n: usize) -> Vec<Vec<u8>> {
    (0..n)
        .map(|i| {
            let mut c = command(rng);
            let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 2.0][i % 4];
            if i % 2 == 0 {
                c.q_sensor_target[rng.random_range(0..4)] = bad;
            } else {
                c.p_sensor_target[rng.random_range(0..3)] = bad;
                if bad == 2.0 {
                    c.q_sensor_target = [0.5, 0.5, 0.5, 0.6];
                }
            }
            frame(
                Command::KIND,
                SCHEMA_VERSION,
                &postcard::to_allocvec(&c).unwrap(),
            )
        })
        .collect()
}

#[test]
fn ten_thousand_mutations_of_every_kind_are_rejected_or_valid() {
    let mut rng = rng();
    let n = 8;
    let tallies = [
        (
            "pose",
            fuzz::<PoseEstimate>(&encoded((0..n).map(|_| pose_estimate(&mut rng))), &[]),
        ),
        (
            "filter",
            fuzz::<FilterState>(&encoded((0..n).map(|_| filter_state(&mut rng))), &[]),
        ),
        (
            "acquisition",
            fuzz::<AcquisitionResult>(&encoded((0..n).map(|_| acquisition(&mut rng))), &[]),
        ),
        (
            "truth",
            fuzz::<TruthMsg>(&encoded((0..n).map(|_| truth(&mut rng))), &[]),
        ),
        (
            "health",
            fuzz::<Health>(&encoded((0..n).map(|_| health(&mut rng))), &[]),
        ),
        ("command", {
            let bad = bad_commands(&mut rng, 1000);
            fuzz::<Command>(&encoded((0..n).map(|_| command(&mut rng))), &bad)
        }),
        (
            "cloud",
            fuzz::<CloudMsg>(&encoded((0..n).map(|i| cloud(&mut rng, i * 3))), &[]),
        ),
    ];
    for (kind, t) in &tallies {
        // Printed for the record (cargo test -- --nocapture).
        println!(
            "{kind:12} {} cases: {} must-reject all rejected; {} flips/random bodies, {} rejected",
            CASES_PER_KIND, t.must_reject, t.maybe, t.maybe_rejected
        );
        // Every class was exercised.
        assert!(t.must_reject > 7 * CASES_PER_KIND / 10 && t.maybe > CASES_PER_KIND / 10);
    }
}
