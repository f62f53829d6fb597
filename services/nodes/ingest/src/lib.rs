//! The `spacepose-ingest` service: [`IngestNode`] over the crop stage of
//! `spacepose_ingest`, its configuration and its wire conversions.
//!
//! Every raw frame is validated and cropped to the region of interest
//! around the latest prediction (the filter's state, or the position of an
//! acquisition), then published on the cloud topic with its own header. A
//! well-formed frame without the target is forwarded all the same: "target
//! not seen" is an observation the tracker must see to report the loss
//! (see `spacepose_ingest`). Bad frames are logged and counted, never fatal.
#![forbid(unsafe_code)]

pub mod config;
pub mod node;
pub mod wire;

pub use config::IngestServiceConfig;
pub use node::IngestNode;
