//! The extent of the dense voxel grids over a point set (the NDT map's
//! cell lookup, ICP's exact and far nearest-point lookups).

use nalgebra::Vector3;

/// A dense voxel grid's box: the bounding box of the points widened by a
/// margin, at a voxel edge coarsened until the voxel count fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VoxelBox {
    /// Lower corner (m).
    pub origin: Vector3<f64>,
    /// Voxel edge actually used (m).
    pub resolution: f64,
    /// Voxels along each axis.
    pub dims: [u32; 3],
}

impl VoxelBox {
    /// The box of `points` (finite, not empty) widened by `margin` on every
    /// side, of voxel edge `resolution` coarsened by ×1.1 steps until it
    /// holds at most `max_voxels`.
    pub(crate) fn fit(
        points: &[Vector3<f64>],
        margin: f64,
        resolution: f64,
        max_voxels: usize,
    ) -> Self {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let origin = lo.add_scalar(-margin);
        let extent = (hi.add_scalar(margin) - origin).map(|e| e.max(0.0));
        let mut h = resolution;
        let dims = loop {
            let d = extent.map(|e| (e / h).floor() as u64 + 1);
            if d.x * d.y * d.z <= max_voxels as u64 {
                break [d.x as u32, d.y as u32, d.z as u32];
            }
            h *= 1.1;
        };
        Self {
            origin,
            resolution: h,
            dims,
        }
    }

    /// Number of voxels.
    pub(crate) fn len(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covers_the_widened_box_and_coarsens_to_fit() {
        let points = [Vector3::new(0.0, 0.0, 0.0), Vector3::new(1.0, 2.0, 0.5)];
        let b = VoxelBox::fit(&points, 0.5, 0.1, 1 << 20);
        assert_eq!(b.origin, Vector3::new(-0.5, -0.5, -0.5));
        assert_eq!(b.resolution, 0.1);
        assert_eq!(b.dims, [21, 31, 16]);
        let small = VoxelBox::fit(&points, 0.5, 0.1, 1000);
        assert!(small.len() <= 1000 && small.resolution > 0.1);
        for a in 0..3 {
            let covered = f64::from(small.dims[a]) * small.resolution;
            assert!(covered >= [2.0, 3.0, 1.5][a]);
        }
    }
}
