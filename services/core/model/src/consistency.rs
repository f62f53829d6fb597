//! Ray consistency of a sensed cloud with the target model at a pose.
//!
//! Each sensed point lies on a ray from the sensor. Cast that ray against
//! the model placed at the estimated pose: where the model's first surface
//! is at the point's range (within a margin) the point is *explained*;
//! where the model's surface is nearer, the sensor saw through a surface
//! the pose says is there, a *free-space violation*; where the ray misses
//! the model or hits it farther away, the point is *unexplained*.
//!
//! This is what a point-to-model distance (ICP's cost, f_CONV of seed 002
//! §4.5) cannot see: a pose flipped onto a near-symmetric twin puts every
//! point close to *some* model surface, while the feature that breaks the
//! symmetry (deos' tower, say) stands in front of surfaces the sensor saw,
//! or is seen where the twin has nothing. Not in the papers; used to rank
//! and reject acquisition hypotheses.

use nalgebra::Vector3;
use spacepose_geometry::Pose;

use crate::Target;

/// Counts of one [`ray_consistency`] query.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RayConsistency {
    /// Finite points cast.
    pub rays: usize,
    /// Points within the margin of the model's first surface on their ray.
    pub explained: usize,
    /// Points behind a model surface by more than the margin (the model
    /// would hide them).
    pub violations: usize,
    /// Points whose ray misses the model, or meets it more than the margin
    /// beyond the point.
    pub unexplained: usize,
}

impl RayConsistency {
    /// `explained / rays` (0 when there are no rays).
    pub fn explained_fraction(&self) -> f64 {
        ratio(self.explained, self.rays)
    }

    /// `violations / rays` (0 when there are no rays).
    pub fn violation_fraction(&self) -> f64 {
        ratio(self.violations, self.rays)
    }
}

/// The range margin of [`ray_consistency`]: `base_m + per_m × range`. The
/// growing part covers the beam footprint, whose range spread on a slanted
/// surface grows with the range (a 0.28° half-angle divergence is 0.005 m
/// of footprint radius per metre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeMargin {
    /// Margin at zero range (m).
    pub base_m: f64,
    /// Added margin per metre of range (m/m).
    pub per_m: f64,
}

impl RangeMargin {
    /// A margin that does not grow with the range.
    pub fn constant(base_m: f64) -> Self {
        Self { base_m, per_m: 0.0 }
    }

    /// The margin at `range_m`.
    pub fn at(&self, range_m: f64) -> f64 {
        self.base_m + self.per_m * range_m
    }
}

fn ratio(n: usize, d: usize) -> f64 {
    if d == 0 { 0.0 } else { n as f64 / d as f64 }
}

/// Casts the ray of every finite point of `points_sensor` (sensor frame,
/// sensor at the origin) against `target` placed at `t_sensor_target`, and
/// sorts the points by [`RayConsistency`]'s classes with the range margin
/// `margin`. Non-finite points and points at the origin are skipped. The
/// cost is one BVH ray cast per point (a few hundred ns each).
pub fn ray_consistency<'a, I>(
    target: &Target,
    t_sensor_target: &Pose,
    points_sensor: I,
    margin: RangeMargin,
) -> RayConsistency
where
    I: IntoIterator<Item = &'a Vector3<f64>>,
{
    let r_target_sensor = t_sensor_target.rotation.inverse();
    // The sensor origin in the target frame: −Rᵀ t.
    let origin = -(r_target_sensor * t_sensor_target.translation);
    let mut c = RayConsistency::default();
    for p in points_sensor {
        let range = p.norm();
        if !range.is_finite() || range <= 0.0 {
            continue;
        }
        c.rays += 1;
        let margin_m = margin.at(range);
        let dir = r_target_sensor * (p / range);
        match target.cast_ray(&origin, &dir, range + margin_m) {
            Some(hit) if hit.distance < range - margin_m => c.violations += 1,
            Some(_) => c.explained += 1,
            None => c.unexplained += 1,
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    /// Points on deos' model seen from 4 m along −z (tower on +x), by casting
    /// a grid of rays at the true pose.
    fn sensed(t: &Target, pose: &Pose) -> Vec<Vector3<f64>> {
        let inv = pose.inverse();
        let mut pts = Vec::new();
        for i in -40..=40 {
            for j in -40..=40 {
                let dir = Vector3::new(f64::from(i) * 0.01, f64::from(j) * 0.01, 1.0).normalize();
                let o = inv.translation;
                let d = inv.rotation * dir;
                if let Some(h) = t.cast_ray(&o, &d, 20.0) {
                    pts.push(dir * h.distance);
                }
            }
        }
        pts
    }

    #[test]
    fn the_true_pose_explains_every_point_and_a_flip_does_not() {
        let t = Target::builtin("deos").unwrap();
        // Looking along the body's −x… at the +x end with its tower, from 4 m.
        let truth = Pose::new(
            Rotation3::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2),
            Vector3::new(0.0, 0.0, 4.0),
        );
        let pts = sensed(&t, &truth);
        assert!(pts.len() > 1000);
        let at_truth = ray_consistency(&t, &truth, &pts, RangeMargin::constant(0.05));
        assert_eq!(at_truth.rays, pts.len());
        assert_eq!(at_truth.explained, pts.len());
        // The 180° twin about the body's y axis: tower away from the sensor;
        // the tower's points are then unexplained (the end face is behind them).
        let flip = Pose::new(
            truth.rotation * Rotation3::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI),
            truth.translation,
        );
        let at_flip = ray_consistency(&t, &flip, &pts, RangeMargin::constant(0.05));
        assert!(at_flip.explained < at_truth.explained);
        assert!(at_flip.unexplained > 0);
        // Seen from the flip's point of view, the true pose puts the tower in
        // front of the end face it saw: violations.
        let pts_flip = sensed(&t, &flip);
        let c = ray_consistency(&t, &truth, &pts_flip, RangeMargin::constant(0.05));
        assert!(c.violations > 0, "{c:?}");
        assert!(c.violation_fraction() > 0.0 && c.explained_fraction() < 1.0);
    }

    #[test]
    fn non_finite_points_are_skipped() {
        let t = Target::builtin("deos").unwrap();
        let pose = Pose::new(Rotation3::identity(), Vector3::new(0.0, 0.0, 4.0));
        let pts = [
            Vector3::new(f64::NAN, 0.0, 1.0),
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, 50.0),
        ];
        let c = ray_consistency(&t, &pose, &pts, RangeMargin::constant(0.05));
        assert_eq!(c.rays, 1);
        // The point 50 m out is behind deos' near face: a violation.
        assert_eq!(c.violations, 1);
        assert_eq!(RayConsistency::default().explained_fraction(), 0.0);
    }
}
