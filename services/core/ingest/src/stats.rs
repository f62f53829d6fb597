//! Counters of the ingest stage since it was created.

/// What the ingest stage has seen and rejected. Frame counters count frames;
/// `*_points` counters count points.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IngestStats {
    /// Frames offered to [`crate::IngestStage::process`].
    pub frames_in: u64,
    /// Frames that came out cropped and filtered (frames without the
    /// target included: they are observations, not rejections).
    pub frames_out: u64,
    /// Well-formed frames that held no point at all (the sensor saw
    /// nothing, e.g. it looked away): forwarded as empty clouds, not rejected.
    pub empty_frames: u64,
    /// Forwarded frames with fewer than `IngestConfig::min_target_points`
    /// points after the crop (empty frames included):
    /// the observation "target not seen".
    pub frames_without_target: u64,
    /// Frames rejected because they exceeded `max_points`.
    pub rejected_oversized: u64,
    /// Frames rejected because every point was non-finite.
    pub rejected_all_non_finite: u64,
    /// Frames rejected for another reason (bad scan interval).
    pub rejected_other: u64,
    /// Frames that had at least one non-finite point (all-NaN frames included).
    pub frames_with_non_finite: u64,
    /// Non-finite points dropped from accepted frames.
    pub non_finite_points: u64,
    /// Finite points outside the region of interest.
    pub cropped_points: u64,
    /// Accepted frames cropped without a trusted prediction.
    pub frames_without_prediction: u64,
    /// Of those, frames cropped to the target found in them
    /// ([`crate::detect`]).
    pub frames_detected: u64,
    /// Predictions ignored because stale or non-finite.
    pub ignored_predictions: u64,
    /// Accepted frames with no point left in the region of interest (empty
    /// frames included).
    pub frames_empty_after_crop: u64,
}
