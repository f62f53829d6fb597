//! What ingest's crop kept of each kind of return, scored with the
//! simulator's labels (truth: scoring only, never an input of the suite).

use serde::Serialize;
use spacepose_geometry::Point;
use spacepose_lidar_sim::{Frame, ReturnKind};
use spacepose_messages::Topic;
use spacepose_runtime::Envelope;

/// Returns in the cropped cloud, by what produced them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct CropKinds {
    /// Echoes of the target.
    pub target: usize,
    /// Echoes of the facility background.
    pub clutter: usize,
    /// Outliers.
    pub outlier: usize,
}

impl CropKinds {
    /// The kinds of the points of `cropped`, an ordered subsequence of
    /// `frame.points` (ingest keeps the points it passes in their order).
    /// A point not found in order is not counted.
    pub fn of(frame: &Frame, cropped: &[Point]) -> CropKinds {
        let mut kinds = CropKinds::default();
        let mut raw = frame.points.iter().zip(&frame.kinds);
        for p in cropped {
            let Some((_, kind)) = raw.by_ref().find(|(q, _)| *q == p) else {
                break;
            };
            match kind {
                ReturnKind::Target => kinds.target += 1,
                ReturnKind::Clutter => kinds.clutter += 1,
                ReturnKind::Outlier => kinds.outlier += 1,
            }
        }
        kinds
    }

    /// The kinds in the cropped cloud among `sent`, if the frame got that
    /// far.
    pub fn of_sent(frame: &Frame, sent: &[Envelope]) -> Option<CropKinds> {
        cropped_cloud(sent).map(|points| CropKinds::of(frame, points))
    }
}

/// Ingest's cropped cloud (`cloud`) among what the suite sent for a frame.
pub fn cropped_cloud(sent: &[Envelope]) -> Option<&[Point]> {
    sent.iter().find_map(|e| match e {
        Envelope::Cloud {
            topic: Topic::Cloud,
            points,
            ..
        } => Some(points.as_slice()),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};

    #[test]
    fn kinds_follow_the_kept_points_in_order() {
        let scenario = build(&ScenarioConfig::default_for(ScenarioKind::Tumbling)).unwrap();
        let at = |x: f32| Point::new(x, 0.0, 10.0, 1.0, 0.5);
        let frame = Frame {
            points: vec![at(0.0), at(1.0), at(2.0), at(3.0)],
            kinds: vec![
                ReturnKind::Target,
                ReturnKind::Clutter,
                ReturnKind::Outlier,
                ReturnKind::Target,
            ],
            scan_start: 0.0,
            scan_end: 1.0,
            truth: scenario.state_at(1.0),
        };
        let kept = CropKinds::of(&frame, &[at(1.0), at(3.0)]);
        assert_eq!(
            kept,
            CropKinds {
                target: 1,
                clutter: 1,
                outlier: 0
            }
        );
        let all = CropKinds::of(&frame, &frame.points);
        assert_eq!((all.target, all.clutter, all.outlier), (2, 1, 1));
        assert_eq!(CropKinds::of(&frame, &[]), CropKinds::default());
    }
}
