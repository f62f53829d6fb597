//! The frame path: what a raw frame becomes before it is registered.
//!
//! One function for the suite's tracker service and for `spacepose eval`:
//! every frame is motion-compensated by the filter's prediction (seed 000
//! Eq. 12) before it is voxel-filtered, once, in the modes that compensate,
//! and only voxel-filtered in the others. The raw points are compensated,
//! not the voxels' mean points: the Livox rosette revisits a voxel at
//! different times within the scan, so a voxel's mean timestamp does not
//! compensate its mean point (compensating voxel means left deblur's pose
//! about 0.28° / 1 cm off). Ingest therefore only crops, and the voxel
//! filter (seed 000 §3.3, keeping each voxel's mean timestamp for CT-NDT)
//! runs here (decision and measurements: `docs/design/frame-path.md`).

use crate::error::TrackError;
use crate::mode::TrackingMode;
use spacepose_filter::{MotionCompensation, Prediction};
use spacepose_geometry::{Point, VoxelFilter};

/// A frame ready for registration.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The voxel-filtered cloud.
    pub cloud: Vec<Point>,
    /// It was motion-compensated to the scan end by the prediction (one
    /// pose is then fitted to it).
    pub compensated: bool,
}

/// The voxel filter and the motion compensation of the frame path.
#[derive(Debug, Clone)]
pub struct FramePipeline {
    voxel: VoxelFilter,
}

impl FramePipeline {
    /// A pipeline with voxels of `leaf_m` (m).
    pub fn new(leaf_m: f64) -> Result<Self, TrackError> {
        Ok(Self {
            voxel: VoxelFilter::new(leaf_m)?,
        })
    }

    /// The cloud `mode` registers: compensated then voxel-filtered in
    /// `deblur` mode, and in `ct-ndt` mode when the frame has fewer than
    /// `ct_ndt_min_points` points after the voxel filter (one pose is then
    /// fitted, see `TrackerConfig::ct_ndt_min_points`); voxel-filtered only
    /// otherwise.
    pub fn prepare(
        &mut self,
        points: &[Point],
        mode: TrackingMode,
        ct_ndt_min_points: usize,
        prediction: &Prediction,
    ) -> Result<Prepared, TrackError> {
        let voxels_only = match mode {
            TrackingMode::Deblur => None,
            TrackingMode::CtNdt => {
                let cloud = self.voxel.filter(points)?.points;
                (cloud.len() >= ct_ndt_min_points).then_some(cloud)
            }
            TrackingMode::Ndt | TrackingMode::Icp => Some(self.voxel.filter(points)?.points),
        };
        Ok(match voxels_only {
            Some(cloud) => Prepared {
                cloud,
                compensated: false,
            },
            None => Prepared {
                cloud: self.compensated(points, prediction)?,
                compensated: true,
            },
        })
    }

    /// The finite points compensated to the scan end by `prediction` (Eq.
    /// 12, one `sin_cos` per point about the fixed axis `R ω`), then
    /// voxel-filtered.
    pub fn compensated(
        &mut self,
        points: &[Point],
        prediction: &Prediction,
    ) -> Result<Vec<Point>, TrackError> {
        let mut finite: Vec<Point> = points.iter().copied().filter(Point::is_finite).collect();
        MotionCompensation::from_prediction(prediction)?.compensate_in_place(&mut finite)?;
        Ok(self.voxel.filter(&finite)?.points)
    }
}
