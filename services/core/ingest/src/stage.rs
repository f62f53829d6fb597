//! The ingest stage: validate, crop to the region of interest.

use crate::config::IngestConfig;
use crate::error::IngestError;
use crate::roi::{Roi, RoiKind, TargetPrediction};
use crate::stats::IngestStats;
use spacepose_geometry::Point;

/// What happened to one accepted frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameReport {
    /// Points received.
    pub input_points: usize,
    /// Non-finite points dropped.
    pub non_finite_points: usize,
    /// Finite points outside the region of interest.
    pub cropped_points: usize,
    /// Points out: the finite points inside the region of interest.
    pub output_points: usize,
    /// False when fewer than `IngestConfig::min_target_points` points came
    /// out: the frame is the observation "target not seen" (still forwarded).
    pub target_seen: bool,
    /// The region used.
    pub roi: RoiKind,
}

/// The crop, with running statistics.
#[derive(Debug, Clone)]
pub struct IngestStage {
    config: IngestConfig,
    stats: IngestStats,
}

impl IngestStage {
    /// A stage after validating `config`.
    pub fn new(config: IngestConfig) -> Result<Self, IngestError> {
        config.validate()?;
        Ok(IngestStage {
            config,
            stats: IngestStats::default(),
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &IngestConfig {
        &self.config
    }

    /// Counters since creation.
    pub fn stats(&self) -> &IngestStats {
        &self.stats
    }

    /// Processes one frame scanned over `[scan_start_s, scan_end_s]` into a new vector.
    pub fn process(
        &mut self,
        points: &[Point],
        scan_start_s: f64,
        scan_end_s: f64,
        prediction: Option<&TargetPrediction>,
    ) -> Result<(Vec<Point>, FrameReport), IngestError> {
        let mut out = Vec::new();
        let report = self.process_into(points, scan_start_s, scan_end_s, prediction, &mut out)?;
        Ok((out, report))
    }

    /// Processes one frame into `out` (cleared first; left empty on error).
    ///
    /// A well-formed frame with no point, or with no (or too few) points
    /// left after the crop, is `Ok` with `out` empty (or small) and
    /// [`FrameReport::target_seen`] false: the caller forwards it, so that
    /// the tracker sees the frame and can report the loss at once.
    ///
    /// # Errors
    /// [`IngestError::Oversized`], [`IngestError::AllNonFinite`],
    /// or [`IngestError::BadScanInterval`]; each is
    /// counted in [`IngestStats`].
    pub fn process_into(
        &mut self,
        points: &[Point],
        scan_start_s: f64,
        scan_end_s: f64,
        prediction: Option<&TargetPrediction>,
        out: &mut Vec<Point>,
    ) -> Result<FrameReport, IngestError> {
        out.clear();
        self.stats.frames_in += 1;
        let result = self.run(points, scan_start_s, scan_end_s, prediction, out);
        if let Err(e) = &result {
            out.clear();
            let s = &mut self.stats;
            match e {
                IngestError::Oversized { .. } => s.rejected_oversized += 1,
                IngestError::AllNonFinite { .. } => {
                    s.rejected_all_non_finite += 1;
                    s.frames_with_non_finite += 1;
                }
                _ => s.rejected_other += 1,
            }
        }
        result
    }

    fn run(
        &mut self,
        points: &[Point],
        scan_start_s: f64,
        scan_end_s: f64,
        prediction: Option<&TargetPrediction>,
        out: &mut Vec<Point>,
    ) -> Result<FrameReport, IngestError> {
        let n = points.len();
        if n > self.config.max_points {
            return Err(IngestError::Oversized {
                points: n,
                capacity: self.config.max_points,
            });
        }
        if !(scan_start_s.is_finite() && scan_end_s.is_finite() && scan_start_s <= scan_end_s) {
            return Err(IngestError::BadScanInterval {
                scan_start_s,
                scan_end_s,
            });
        }
        let (roi, issue) = Roi::for_frame(&self.config, prediction, scan_start_s, scan_end_s);
        let roi = roi.detect_in(points, &self.config);
        let crop = crop_into(&roi, points, out);
        // An empty frame (n = 0) is not "all non-finite": it goes through.
        if n > 0 && crop.non_finite == n {
            return Err(IngestError::AllNonFinite { points: n });
        }
        let target_seen = out.len() >= self.config.min_target_points;
        let s = &mut self.stats;
        s.frames_out += 1;
        s.empty_frames += u64::from(n == 0);
        s.frames_without_target += u64::from(!target_seen);
        s.frames_with_non_finite += u64::from(crop.non_finite > 0);
        s.non_finite_points += crop.non_finite as u64;
        s.cropped_points += crop.outside as u64;
        s.ignored_predictions += u64::from(issue.is_some());
        s.frames_without_prediction += u64::from(roi.centre().is_none());
        s.frames_detected += u64::from(roi.detection().is_some());
        s.frames_empty_after_crop += u64::from(out.is_empty());
        Ok(FrameReport {
            input_points: n,
            non_finite_points: crop.non_finite,
            cropped_points: crop.outside,
            output_points: out.len(),
            target_seen,
            roi: roi.kind(),
        })
    }
}

/// Counts of one crop.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CropCounts {
    /// Points with a NaN or infinite field.
    pub non_finite: usize,
    /// Finite points outside the region.
    pub outside: usize,
}

/// Copies the finite points of `points` inside `roi` into `out` (cleared
/// first), in input (time) order.
pub fn crop_into(roi: &Roi, points: &[Point], out: &mut Vec<Point>) -> CropCounts {
    out.clear();
    let mut counts = CropCounts::default();
    for p in points {
        if !p.is_finite() {
            counts.non_finite += 1;
        } else if roi.contains(p) {
            out.push(*p);
        } else {
            counts.outside += 1;
        }
    }
    counts
}
