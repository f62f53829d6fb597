//! The suite's messages as Foxglove schemas, written to MCAP.
