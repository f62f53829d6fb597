//! Any message of the suite, as a node receives or sends it: one enum for
//! the fixed-size messages, one borrowed view for clouds.

use crate::names::Topic;
use crate::{AcquisitionResult, CloudHeader, Command, FilterState, Health, PoseEstimate, TruthMsg};
use spacepose_geometry::Point;

/// A fixed-size message of one of the topics that are not clouds. The
/// variants are the wire structs themselves (`Copy`, shared-memory
/// layout); boxing the large ones would allocate per message.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Message {
    /// On [`Topic::Pose`].
    Pose(PoseEstimate),
    /// On [`Topic::FilterState`].
    FilterState(FilterState),
    /// On [`Topic::Acquisition`].
    Acquisition(AcquisitionResult),
    /// On [`Topic::Truth`].
    Truth(TruthMsg),
    /// On [`Topic::Health`].
    Health(Health),
    /// On [`Topic::Command`].
    Command(Command),
}

impl Message {
    /// The topic the message travels on.
    pub fn topic(&self) -> Topic {
        match self {
            Message::Pose(_) => Topic::Pose,
            Message::FilterState(_) => Topic::FilterState,
            Message::Acquisition(_) => Topic::Acquisition,
            Message::Truth(_) => Topic::Truth,
            Message::Health(_) => Topic::Health,
            Message::Command(_) => Topic::Command,
        }
    }
}

/// A cloud as a node sees it: the header and the points, borrowed from the
/// transport (shared memory on iceoryx2).
#[derive(Debug, Clone, Copy)]
pub struct Cloud<'a> {
    /// [`Topic::RawCloud`] or [`Topic::Cloud`].
    pub topic: Topic,
    /// Sequence, scan interval, sensor.
    pub header: &'a CloudHeader,
    /// The points, in acquisition order.
    pub points: &'a [Point],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CommandKind, Name};

    #[test]
    fn every_message_knows_its_topic() {
        let name = Name::new("t").unwrap();
        let all = [
            (Message::Pose(PoseEstimate::new()), Topic::Pose),
            (Message::FilterState(FilterState::new()), Topic::FilterState),
            (
                Message::Acquisition(AcquisitionResult::new()),
                Topic::Acquisition,
            ),
            (Message::Truth(TruthMsg::new()), Topic::Truth),
            (Message::Health(Health::new(name, name, 1)), Topic::Health),
            (
                Message::Command(Command::new(CommandKind::Reinit, name)),
                Topic::Command,
            ),
        ];
        for (m, t) in all {
            assert_eq!(m.topic(), t);
            assert!(!t.is_cloud());
        }
    }
}
