//! Recorded lidar frames in: PCD/PLY directories, MCAP files (Foxglove
//! `PointCloud`) and ROS 2 bags (`sensor_msgs/msg/PointCloud2`), each frame
//! with per-point times.
//!
//! [`open`] takes a path and [`InputOptions`] and gives a [`Recording`]
//! whose [`Recording::frames`] are [`InputFrame`]s in order:
//! - a directory of `frame_NNNNNN.pcd` / `.ply` (optional `truth.csv` scan
//!   times) — [`pcd_dir`];
//! - an MCAP file, or a ROS 2 bag directory (`metadata.yaml` and `*.mcap`):
//!   channels of `sensor_msgs/msg/PointCloud2` (CDR, [`pointcloud2`]) or
//!   `foxglove.PointCloud` (protobuf, [`foxglove_cloud`]), chosen by topic
//!   ([`channels`]).
//!
//! **Per-point times** come from a field chosen by the
//! [`spacepose_geometry::TimeMapping`] (`t`, `time`, `timestamp`, Livox
//! `offset_time`, or a configured name, unit and base). When a cloud has
//! none they are **derived**: linear in point order over the scan interval
//! (the `truth.csv` row, the spacepose header, or the reference time plus
//! the scan period), and the frame says so ([`InputFrame::times_derived`])
//! so the caller warns and counts it. The scan period for derived times is
//! [`InputOptions::scan_period_s`], else the `truth.csv` median period,
//! else [`DEFAULT_SCAN_PERIOD_S`] (0.1 s, the 10 Hz of common spinning
//! lidars): a missing time field never reads as t = 0.
//!
//! Nothing here panics on file content: corrupt files and unsupported
//! layouts are [`InputError`] values, one per frame, and the reading goes on.
#![forbid(unsafe_code)]

mod bounded;
mod cdr;
pub mod channels;
mod chunks;
pub mod error;
pub mod foxglove_cloud;
pub mod frame;
pub mod mcap_source;
pub mod messages;
pub mod options;
mod packed;
pub mod pcd_dir;
pub mod pointcloud2;
pub mod recording;
pub mod scalar;
pub mod truth;

#[cfg(test)]
mod test_support;

pub use channels::{ChannelInfo, CloudKind};
pub use error::{CloudError, InputError};
pub use foxglove_cloud::SpaceposeHeader;
pub use frame::{InputFrame, ScanTimeSource};
pub use mcap_source::{McapCursor, McapSource};
pub use messages::{McapContents, TopicMessage, read_messages};
pub use options::{DEFAULT_SCAN_PERIOD_S, InputOptions};
pub use pcd_dir::PcdDir;
pub use recording::{FrameCursor, Recording, open};
pub use spacepose_geometry::{PointTimes, TimeBase, TimeField, TimeMapping, TimeUnit};
pub use truth::{ScanTimes, TruthTimes};
