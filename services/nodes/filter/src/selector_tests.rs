use super::*;
use crate::failover::{ChangeCause, FailoverPolicy};

const MS: i64 = 1_000_000;
/// Frame k's cloud is published at k × 200 ms; the deadline is 100 ms.
const DEADLINE_MS: f64 = 100.0;

fn cloud_ns(seq: u64) -> i64 {
    seq as i64 * 200 * MS
}

fn cand(instance: &str, seq: u64, quality: Quality) -> Candidate<&'static str> {
    Candidate {
        instance: instance.to_string(),
        sequence: seq,
        cloud_published_ns: cloud_ns(seq),
        quality,
        payload: "",
    }
}

fn redundant() -> FrameSelector<&'static str> {
    FrameSelector::new(Some("tracker-a".into()), DEADLINE_MS, 16)
}

/// (sequence, instance, reason) of each decision.
fn summary(choices: &[Choice<&'static str>]) -> Vec<(u64, String, Reason)> {
    choices
        .iter()
        .map(|c| (c.candidate.sequence, c.candidate.instance.clone(), c.reason))
        .collect()
}

#[test]
fn without_a_primary_the_first_arrival_wins() {
    let mut s = FrameSelector::new(None, DEADLINE_MS, 8);
    let (o, d) = s.offer(cand("tracker-b", 5, Quality::Good), cloud_ns(5));
    assert_eq!(o, Offer::Chosen);
    assert_eq!(
        summary(&d),
        vec![(5, "tracker-b".into(), Reason::FirstArrival)]
    );
    let (o, d) = s.offer(cand("tracker-a", 5, Quality::Good), cloud_ns(5));
    assert_eq!((o, d.len()), (Offer::Duplicate, 0));
    // Out of order but inside the window: still the first of its frame.
    assert_eq!(s.offer(cand("a", 4, Quality::Good), 0).0, Offer::Chosen);
    assert_eq!(s.newest(), Some(5));
}

#[test]
fn the_primary_on_time_wins_even_after_a_standby() {
    let mut s = redundant();
    let (o, d) = s.offer(cand("tracker-b", 1, Quality::Good), cloud_ns(1) + 10 * MS);
    assert_eq!((o, d.len()), (Offer::Held, 0));
    assert_eq!(s.next_deadline_ns(), Some(cloud_ns(1) + 100 * MS));
    let (o, d) = s.offer(cand("tracker-a", 1, Quality::Good), cloud_ns(1) + 40 * MS);
    assert_eq!(o, Offer::Chosen);
    assert_eq!(summary(&d), vec![(1, "tracker-a".into(), Reason::Primary)]);
    assert!(s.poll(cloud_ns(1) + 500 * MS).is_empty());
    assert_eq!(s.next_deadline_ns(), None);
}

#[test]
fn a_missing_primary_is_replaced_by_the_standby_at_the_deadline() {
    let mut s = redundant();
    s.offer(cand("tracker-b", 2, Quality::Good), cloud_ns(2) + 20 * MS);
    // Before the deadline: still waiting for the primary.
    assert!(s.poll(cloud_ns(2) + 99 * MS).is_empty());
    let d = s.poll(cloud_ns(2) + 101 * MS);
    assert_eq!(
        summary(&d),
        vec![(2, "tracker-b".into(), Reason::PrimaryMissing)]
    );
    // A standby arriving after the deadline is taken at once.
    let (o, d) = s.offer(cand("tracker-b", 3, Quality::Good), cloud_ns(3) + 150 * MS);
    assert_eq!(o, Offer::Chosen);
    assert_eq!(
        summary(&d),
        vec![(3, "tracker-b".into(), Reason::PrimaryMissing)]
    );
}

#[test]
fn a_late_primary_is_a_duplicate_once_the_standby_was_taken() {
    let mut s = redundant();
    s.offer(cand("tracker-b", 4, Quality::Good), cloud_ns(4) + 30 * MS);
    assert_eq!(s.poll(cloud_ns(4) + 120 * MS).len(), 1);
    let (o, d) = s.offer(cand("tracker-a", 4, Quality::Good), cloud_ns(4) + 130 * MS);
    assert_eq!((o, d.len()), (Offer::Duplicate, 0));
    // Late with no standby at all: late is better than nothing.
    let (o, d) = s.offer(cand("tracker-a", 5, Quality::Good), cloud_ns(5) + 180 * MS);
    assert_eq!(o, Offer::Chosen);
    assert_eq!(
        summary(&d),
        vec![(5, "tracker-a".into(), Reason::PrimaryLate)]
    );
}

#[test]
fn an_inconsistent_or_lost_primary_gives_way_to_a_good_standby() {
    let mut s = redundant();
    // Primary first, inconsistent: held until the standby arrives.
    let (o, d) = s.offer(
        cand("tracker-a", 6, Quality::Inconsistent),
        cloud_ns(6) + 10 * MS,
    );
    assert_eq!((o, d.len()), (Offer::Held, 0));
    let (o, d) = s.offer(cand("tracker-b", 6, Quality::Good), cloud_ns(6) + 20 * MS);
    assert_eq!(o, Offer::Chosen);
    assert_eq!(
        summary(&d),
        vec![(
            6,
            "tracker-b".into(),
            Reason::PrimaryUnusable(Quality::Inconsistent)
        )]
    );
    // Standby first, then a lost primary: the standby is taken at once.
    s.offer(cand("tracker-b", 7, Quality::Good), cloud_ns(7) + 10 * MS);
    let (o, d) = s.offer(
        cand("tracker-a", 7, Quality::NotTracking),
        cloud_ns(7) + 20 * MS,
    );
    assert_eq!(o, Offer::Superseded);
    assert_eq!(
        summary(&d),
        vec![(
            7,
            "tracker-b".into(),
            Reason::PrimaryUnusable(Quality::NotTracking)
        )]
    );
    // Both unusable: at the deadline the primary's is the fallback.
    s.offer(
        cand("tracker-a", 8, Quality::Inconsistent),
        cloud_ns(8) + 10 * MS,
    );
    s.offer(
        cand("tracker-b", 8, Quality::NotTracking),
        cloud_ns(8) + 20 * MS,
    );
    let d = s.poll(cloud_ns(8) + 101 * MS);
    assert_eq!(summary(&d), vec![(8, "tracker-a".into(), Reason::Fallback)]);
}

#[test]
fn without_failover_a_recovered_primary_is_taken_again() {
    let mut s = redundant().with_failover(FailoverPolicy {
        promote_after_misses: 0,
        revert_after_frames: 0,
    });
    let mut chosen = Vec::new();
    for seq in 0..10u64 {
        let t0 = cloud_ns(seq);
        // The primary is dead for frames 3 to 5.
        let primary_up = !(3..=5).contains(&seq);
        let (_, d) = s.offer(cand("tracker-b", seq, Quality::Good), t0 + 15 * MS);
        chosen.extend(summary(&d));
        if primary_up {
            let (_, d) = s.offer(cand("tracker-a", seq, Quality::Good), t0 + 30 * MS);
            chosen.extend(summary(&d));
        }
        chosen.extend(summary(&s.poll(t0 + 150 * MS)));
    }
    let by: Vec<&str> = chosen.iter().map(|c| c.1.as_str()).collect();
    assert_eq!(chosen.len(), 10, "{chosen:?}");
    assert!(chosen.iter().enumerate().all(|(k, c)| c.0 == k as u64));
    assert_eq!(
        by,
        [
            "tracker-a",
            "tracker-a",
            "tracker-a",
            "tracker-b",
            "tracker-b",
            "tracker-b",
            "tracker-a",
            "tracker-a",
            "tracker-a",
            "tracker-a"
        ]
    );
}

#[test]
fn decisions_keep_frame_order() {
    let mut s = redundant();
    // Frame 1 waits for the primary; frame 2's primary arrives first.
    s.offer(cand("tracker-b", 1, Quality::Good), cloud_ns(1) + 10 * MS);
    let (_, d) = s.offer(cand("tracker-a", 2, Quality::Good), cloud_ns(2) + 10 * MS);
    assert_eq!(
        summary(&d),
        vec![
            (1, "tracker-b".into(), Reason::PrimaryMissing),
            (2, "tracker-a".into(), Reason::Primary)
        ]
    );
}

#[test]
fn the_primary_switches_at_a_frame_boundary() {
    let mut s = redundant();
    s.offer(cand("tracker-a", 1, Quality::Good), cloud_ns(1) + 10 * MS);
    // Frame 2: the new instance's estimate is held as a standby, then the
    // swap command makes it the primary before the old one answers.
    s.offer(cand("tracker-s1", 2, Quality::Good), cloud_ns(2) + 10 * MS);
    let d = s.set_primary("tracker-s1");
    assert_eq!(s.primary(), Some("tracker-s1"));
    assert_eq!(summary(&d), vec![(2, "tracker-s1".into(), Reason::Primary)]);
    let (o, d) = s.offer(cand("tracker-a", 2, Quality::Good), cloud_ns(2) + 20 * MS);
    assert_eq!((o, d.len()), (Offer::Duplicate, 0));
    // From frame 3 on, the old primary is a standby: held, then superseded.
    let (o, _) = s.offer(cand("tracker-a", 3, Quality::Good), cloud_ns(3) + 5 * MS);
    assert_eq!(o, Offer::Held);
    let (_, d) = s.offer(cand("tracker-s1", 3, Quality::Good), cloud_ns(3) + 10 * MS);
    assert_eq!(summary(&d), vec![(3, "tracker-s1".into(), Reason::Primary)]);
    assert_eq!(s.next_deadline_ns(), None);
}

#[test]
fn the_window_bounds_memory_and_a_restarted_source_is_followed() {
    let mut s = redundant();
    for k in 0..100 {
        s.offer(cand("tracker-a", k, Quality::Good), cloud_ns(k));
    }
    assert!(s.decided.len() <= 17, "{}", s.decided.len());
    assert_eq!(
        s.offer(cand("tracker-a", 80, Quality::Good), 0).0,
        Offer::Stale
    );
    assert_eq!(
        s.offer(cand("tracker-a", 95, Quality::Good), 0).0,
        Offer::Duplicate
    );
    assert_eq!(
        s.offer(cand("tracker-a", 0, Quality::Good), cloud_ns(0)).0,
        Offer::Chosen
    );
    assert_eq!(s.newest(), Some(0));
    s.reset();
    assert_eq!(s.newest(), None);
}

/// One estimate as a tracker delivers it: instance, ms after its frame's
/// cloud, quality.
type Delivery = (&'static str, i64, Quality);

/// A decision and when it was made (ms after its frame's cloud).
#[derive(Debug, Clone, PartialEq)]
struct Decided {
    sequence: u64,
    instance: String,
    reason: Reason,
    after_ms: f64,
}

/// Drives `s` like the filter's loop, with explicit times: every delivery
/// of `frames` frames in time order, and a poll just after each frame
/// deadline that comes first (the loop wakes at `next_deadline_ns`).
fn drive(
    s: &mut FrameSelector<&'static str>,
    frames: std::ops::Range<u64>,
    deliveries: impl Fn(u64) -> Vec<Delivery>,
) -> Vec<Decided> {
    let mut events: Vec<(i64, u64, &'static str, Quality)> = frames
        .flat_map(|seq| {
            deliveries(seq)
                .into_iter()
                .map(move |(i, ms, q)| (cloud_ns(seq) + ms * MS, seq, i, q))
        })
        .collect();
    events.sort_by_key(|e| e.0);
    let mut out = Vec::new();
    let mut record = |choices: Vec<Choice<&'static str>>, now: i64| {
        for c in choices {
            out.push(Decided {
                sequence: c.candidate.sequence,
                instance: c.candidate.instance.clone(),
                reason: c.reason,
                after_ms: (now - c.candidate.cloud_published_ns) as f64 / MS as f64,
            });
        }
    };
    let poll_until = |s: &mut FrameSelector<&'static str>,
                      t: i64,
                      record: &mut dyn FnMut(Vec<Choice<&'static str>>, i64)| {
        while let Some(d) = s.next_deadline_ns().filter(|d| *d < t) {
            record(s.poll(d + 1), d + 1);
        }
    };
    for (t, seq, instance, q) in events {
        poll_until(s, t, &mut record);
        let (_, d) = s.offer(cand(instance, seq, q), t);
        record(d, t);
    }
    poll_until(s, i64::MAX, &mut record);
    out
}

/// Both trackers healthy: the standby answers first (15 ms), the primary at
/// 30 ms; `dead` frames have nothing from `who`.
fn both(who: &'static str, dead: std::ops::RangeInclusive<u64>) -> impl Fn(u64) -> Vec<Delivery> {
    move |seq| {
        [
            ("tracker-a", 30, Quality::Good),
            ("tracker-b", 15, Quality::Good),
        ]
        .into_iter()
        .filter(|(i, _, _)| !(*i == who && dead.contains(&seq)))
        .collect()
    }
}

fn instances(d: &[Decided]) -> Vec<&str> {
    d.iter().map(|x| x.instance.as_str()).collect()
}

/// Exactly one decision per frame, in frame order.
fn assert_one_per_frame(d: &[Decided], frames: std::ops::Range<u64>) {
    let seqs: Vec<u64> = d.iter().map(|x| x.sequence).collect();
    assert_eq!(seqs, frames.collect::<Vec<_>>(), "{d:?}");
}

#[test]
fn a_dead_primary_is_replaced_by_a_promoted_standby_after_two_misses() {
    let mut s = redundant();
    // The primary dies after frame 3 and never comes back.
    let d = drive(&mut s, 0..12, both("tracker-a", 4..=100));
    assert_one_per_frame(&d, 0..12);
    let waits: Vec<f64> = d.iter().map(|x| x.after_ms).collect();
    // Frames 0-3: the primary at 30 ms. Frames 4, 5: the standby at the
    // deadline. From frame 6 on: the promoted standby at once (15 ms).
    assert_eq!(&waits[..4], &[30.0; 4]);
    assert!(
        waits[4..6].iter().all(|w| (100.0..101.0).contains(w)),
        "{waits:?}"
    );
    assert_eq!(&waits[6..], &[15.0; 6]);
    assert_eq!(d[4].reason, Reason::PrimaryMissing);
    assert!(d[6..].iter().all(|x| x.reason == Reason::Primary));
    assert_eq!(instances(&d[4..]), ["tracker-b"; 8]);
    assert_eq!(
        (s.primary(), s.preferred()),
        (Some("tracker-b"), Some("tracker-a"))
    );
    let changes = s.take_role_changes();
    assert_eq!(changes.len(), 1, "{changes:?}");
    assert_eq!(
        (
            changes[0].from.as_str(),
            changes[0].to.as_str(),
            changes[0].cause,
            changes[0].from_frame
        ),
        (
            "tracker-a",
            "tracker-b",
            ChangeCause::Promoted { misses: 2 },
            6
        )
    );
    assert!(s.take_role_changes().is_empty());
}

#[test]
fn one_missed_frame_does_not_promote() {
    let mut s = redundant();
    // Misses on frames 3, 5 and 7: never two in a row.
    let d = drive(&mut s, 0..10, move |seq| {
        both("tracker-a", 0..=0)(seq)
            .into_iter()
            .filter(|(i, _, _)| !(*i == "tracker-a" && [3, 5, 7].contains(&seq)))
            .collect()
    });
    assert_one_per_frame(&d, 0..10);
    assert_eq!(s.primary(), Some("tracker-a"));
    assert!(s.take_role_changes().is_empty());
    // A late primary counts as a miss too, and so does an unusable standby's
    // fallback; but two misses need a good standby to promote.
    let mut s = redundant();
    let d = drive(&mut s, 0..6, |seq| {
        if seq < 2 {
            both("tracker-a", 0..=0)(seq)
        } else {
            vec![
                ("tracker-a", 150, Quality::Good),
                ("tracker-b", 15, Quality::NotTracking),
            ]
        }
    });
    assert_one_per_frame(&d, 0..6);
    assert_eq!(s.primary(), Some("tracker-a"), "{d:?}");
}

#[test]
fn a_held_standby_estimate_is_taken_at_the_promotion() {
    // A deadline longer than the frame period: frame k+1's standby estimate
    // is already held when frame k's deadline promotes the standby.
    let mut s = FrameSelector::new(Some("tracker-a".into()), 300.0, 16);
    let d = drive(&mut s, 0..6, both("tracker-a", 2..=100));
    assert_one_per_frame(&d, 0..6);
    // Frames 2, 3 at their deadline (300 ms); frame 4 was held since
    // 15 ms and is decided with frame 3 (at 100 ms after its cloud);
    // frame 5 on arrival.
    let waits: Vec<f64> = d.iter().map(|x| x.after_ms).collect();
    assert!(
        (300.0..301.0).contains(&waits[2]) && (300.0..301.0).contains(&waits[3]),
        "{waits:?}"
    );
    assert!((100.0..101.0).contains(&waits[4]), "{waits:?}");
    assert_eq!((d[4].reason, waits[5]), (Reason::Primary, 15.0));
}

#[test]
fn the_recovered_primary_takes_the_role_back_after_five_good_frames() {
    let mut s = redundant();
    // Dead on frames 3-6, back from frame 7 (a restart).
    let d = drive(&mut s, 0..20, both("tracker-a", 3..=6));
    assert_one_per_frame(&d, 0..20);
    let by = instances(&d);
    // 0-2 a; 3, 4 b at the deadline; 5-6 b promoted; 7-11 b while a
    // delivers its five good frames (its estimates come after b's); on
    // frame 11 a's fifth estimate arrives after b's was taken, so a is
    // the primary from frame 12 on.
    assert_eq!(&by[..3], ["tracker-a"; 3]);
    assert_eq!(&by[3..12], ["tracker-b"; 9]);
    assert_eq!(&by[12..], ["tracker-a"; 8]);
    let changes = s.take_role_changes();
    assert_eq!(changes.len(), 2, "{changes:?}");
    assert_eq!(changes[1].cause, ChangeCause::Reverted { frames: 5 });
    assert_eq!(
        (changes[1].to.as_str(), changes[1].from_frame),
        ("tracker-a", 12)
    );
    // No frame after the promotion waits for a deadline.
    assert!(d[5..].iter().all(|x| x.after_ms <= 30.0), "{d:?}");
    assert_eq!(
        (s.primary(), s.preferred()),
        (Some("tracker-a"), Some("tracker-a"))
    );
}

#[test]
fn a_late_or_inconsistent_estimate_restarts_the_revert_count() {
    let mut s = redundant();
    let d = drive(&mut s, 0..20, |seq| match seq {
        2..=3 => vec![("tracker-b", 15, Quality::Good)],
        // Frame 6: late (a frozen process thawed); frame 9: inconsistent.
        6 => vec![
            ("tracker-b", 15, Quality::Good),
            ("tracker-a", 180, Quality::Good),
        ],
        9 => vec![
            ("tracker-b", 15, Quality::Good),
            ("tracker-a", 30, Quality::Inconsistent),
        ],
        _ => both("tracker-a", 0..=0)(seq),
    });
    assert_one_per_frame(&d, 0..20);
    // Good and on time on 4, 5; 7, 8; then 10..=14: back from frame 15.
    let changes = s.take_role_changes();
    assert_eq!(changes.len(), 2, "{changes:?}");
    assert_eq!(changes[1].from_frame, 15);
    assert_eq!(
        instances(&d)[14..],
        [
            "tracker-b",
            "tracker-a",
            "tracker-a",
            "tracker-a",
            "tracker-a",
            "tracker-a"
        ]
    );
}

#[test]
fn non_revertive_failover_keeps_the_promoted_standby_until_it_fails() {
    let mut s = redundant().with_failover(FailoverPolicy {
        promote_after_misses: 2,
        revert_after_frames: 0,
    });
    // a dead on 2-4; b dead on 10-11 (a healthy since 5).
    let d = drive(&mut s, 0..16, |seq| {
        both("tracker-a", 2..=4)(seq)
            .into_iter()
            .filter(|(i, _, _)| !(*i == "tracker-b" && (10..=11).contains(&seq)))
            .collect()
    });
    assert_one_per_frame(&d, 0..16);
    let by = instances(&d);
    assert_eq!(&by[..2], ["tracker-a"; 2]);
    assert_eq!(&by[2..10], ["tracker-b"; 8]);
    assert_eq!(&by[10..], ["tracker-a"; 6]);
    // b's misses (10, 11) wait for the deadline, then a is promoted.
    assert!(d[10].after_ms >= 100.0 && d[12].after_ms == 30.0, "{d:?}");
    let causes: Vec<ChangeCause> = s.take_role_changes().iter().map(|c| c.cause).collect();
    assert_eq!(
        causes,
        [
            ChangeCause::Promoted { misses: 2 },
            ChangeCause::Promoted { misses: 2 }
        ]
    );
}

#[test]
fn a_swap_after_a_promotion_sets_both_roles() {
    let mut s = redundant();
    drive(&mut s, 0..8, both("tracker-a", 2..=100));
    assert_eq!(s.primary(), Some("tracker-b"));
    assert!(s.set_primary("tracker-s1").is_empty());
    assert_eq!(
        (s.primary(), s.preferred()),
        (Some("tracker-s1"), Some("tracker-s1"))
    );
    let (o, d) = s.offer(cand("tracker-s1", 8, Quality::Good), cloud_ns(8) + 20 * MS);
    assert_eq!((o, d[0].reason), (Offer::Chosen, Reason::Primary));
}
