//! One cloud's answer, and the check of its points before the tracker sees
//! them.
//!
//! An empty cloud (or one below `loss.min_points`) is not bad input: ingest
//! forwards a well-formed frame without the target as the observation
//! "target not seen", and the tracker answers it `lost` with no measurement.
//! Bad input is a frame above `max_points`, or one whose points are all
//! non-finite; a frame with some non-finite points is tracked on the rest.

use spacepose_geometry::Point;
use spacepose_messages::PoseEstimate;
use spacepose_tracker::TrackError;
use std::borrow::Cow;

/// Why a frame was not handed to the tracker (or only partly).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputIssue {
    /// More points than `max_points`.
    Oversized {
        /// Points in the frame.
        points: usize,
        /// The limit.
        max_points: usize,
    },
    /// Some points had NaN/infinite values; they were dropped. With
    /// `kept == 0` the frame was not tracked.
    NonFinite {
        /// Points dropped.
        dropped: usize,
        /// Finite points kept.
        kept: usize,
    },
}

/// The answer for one cloud.
#[derive(Debug)]
pub struct FrameResult {
    /// The estimate to publish (always one per frame).
    pub estimate: PoseEstimate,
    /// A problem with the input, to log and count.
    pub issue: Option<InputIssue>,
    /// A tracker error (misuse, bad scan times), to log and count.
    pub error: Option<TrackError>,
    /// Why the estimate is degraded or lost (empty when tracking).
    pub reason: String,
}

impl FrameResult {
    /// The answer `estimate` (a `lost` one, to be filled), no issue yet.
    pub fn new(estimate: PoseEstimate) -> Self {
        FrameResult {
            estimate,
            issue: None,
            error: None,
            reason: String::new(),
        }
    }
}

/// The finite points of an acceptable frame; `None` (and the issue and
/// reason recorded in `result`) when the frame cannot be tracked at all.
/// A few non-finite points are dropped, and recorded as an issue too.
pub fn usable_points<'a>(
    points: &'a [Point],
    max_points: usize,
    result: &mut FrameResult,
) -> Option<Cow<'a, [Point]>> {
    // An empty cloud is no issue: it goes to the tracker (no measurement).
    if points.len() > max_points {
        let issue = InputIssue::Oversized {
            points: points.len(),
            max_points,
        };
        result.reason = format!("input rejected: {issue:?}");
        result.issue = Some(issue);
        return None;
    }
    let kept = points.iter().filter(|p| p.is_finite()).count();
    if kept == points.len() {
        return Some(Cow::Borrowed(points));
    }
    result.issue = Some(InputIssue::NonFinite {
        dropped: points.len() - kept,
        kept,
    });
    if kept > 0 {
        let finite = points.iter().copied().filter(Point::is_finite).collect();
        return Some(Cow::Owned(finite));
    }
    result.reason = "every point is non-finite".into();
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(x: f32) -> Point {
        Point::new(x, 0.0, 10.0, 1.0, 0.5)
    }

    #[test]
    fn oversized_all_nan_and_partly_nan_frames_are_told_apart() {
        let mut r = FrameResult::new(PoseEstimate::new());
        let good = vec![point(0.0); 4];
        assert!(matches!(
            usable_points(&good, 4, &mut r),
            Some(Cow::Borrowed(_))
        ));
        assert_eq!((r.issue, r.reason.as_str()), (None, ""));
        assert!(usable_points(&[], 4, &mut r).is_some_and(|p| p.is_empty()));
        assert!(usable_points(&good, 3, &mut r).is_none());
        assert_eq!(
            r.issue,
            Some(InputIssue::Oversized {
                points: 4,
                max_points: 3
            })
        );
        let mut r = FrameResult::new(PoseEstimate::new());
        let some = vec![point(1.0), point(f32::NAN), point(2.0)];
        let kept = usable_points(&some, 4, &mut r).unwrap();
        assert_eq!(kept.len(), 2);
        assert_eq!(
            r.issue,
            Some(InputIssue::NonFinite {
                dropped: 1,
                kept: 2
            })
        );
        let mut r = FrameResult::new(PoseEstimate::new());
        assert!(usable_points(&[point(f32::INFINITY)], 4, &mut r).is_none());
        assert!(r.reason.contains("non-finite"), "{}", r.reason);
    }
}
