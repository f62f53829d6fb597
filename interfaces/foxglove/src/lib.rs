//! The suite's messages as Foxglove well-known schemas: an MCAP recorder
//! of a run and a live view (a Foxglove WebSocket server) over the
//! `foxglove` SDK.
//!
//! There is one conversion per message: clouds to `foxglove.PointCloud`
//! ([`cloud`]), poses, truth and filter states to `foxglove.PoseInFrame`
//! and `foxglove.FrameTransform` ([`pose`]), the target mesh to
//! `foxglove.SceneUpdate` ([`scene`]), and every message's status fields to
//! JSON channels whose records are the telemetry JSON of
//! `spacepose_messages::telemetry` (acquisitions: [`records`]).
//!
//! Log times are the sensor clock ([`stamp`]): a message is logged at the
//! time of validity of its frame, so a recording sorts the same way however
//! the processes were scheduled. The [`Recorder`] and the [`LiveView`] log
//! through the same channel logger, so a file and the live link carry the
//! same channels; the live view decimates clouds for the link (frames and
//! a point budget) and adds the trajectory. Each owns its own SDK context,
//! so two of them in one process never share channels. Topics and frames
//! are in [`topics`] and `docs/recording.md`.
#![forbid(unsafe_code)]

mod channels;
pub mod cloud;
pub mod error;
pub mod json;
pub mod live;
mod log;
pub mod pose;
pub mod recorder;
pub mod records;
pub mod scene;
pub mod stamp;
pub mod topics;

pub use cloud::{CloudHeaderRecord, POINT_STRIDE, point_cloud};
pub use error::RecordError;
pub use live::{LiveOptions, LiveStats, LiveView};
pub use recorder::{Compression, RecordOptions, Recorder};
pub use records::AcquisitionRecord;
pub use scene::{TargetMesh, target_scene};
pub use stamp::{log_time_ns, timestamp};
