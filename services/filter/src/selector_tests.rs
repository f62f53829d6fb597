use super::*;

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
fn a_recovered_primary_is_taken_again() {
    let mut s = redundant();
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
