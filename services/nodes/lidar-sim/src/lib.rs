//! The `spacepose-lidar-sim` service, the sensor-driver stand-in:
//! [`LidarSimNode`] over `spacepose_lidar_sim::FrameSource`, its
//! configuration, its checkpoint and its wire conversions.
//!
//! It publishes simulated raw frames (clutter on by default) at the sensor
//! rate, the ground truth of each frame on the truth topic, and, with
//! `truth_init = true`, one `AcquisitionResult { method: truth }` for the
//! first frame (published before that frame): the documented exception for
//! runs without the init service.
//!
//! A restarted instance continues the scenario where the dead one stopped:
//! it resumes at the frame now due from the checkpoint its predecessor
//! left (`checkpoint_file`, see [`checkpoint`] for why a checkpoint rather
//! than a shared start instant); the frames missed meanwhile are missing.
//!
//! [`wire`] turns a simulated frame into its messages; a one-process
//! evaluation calls it too, so it feeds the suite what this sensor does.
#![forbid(unsafe_code)]

pub mod checkpoint;
pub mod config;
pub mod node;
pub mod wire;

pub use config::LidarSimConfig;
pub use node::LidarSimNode;
