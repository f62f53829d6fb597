//! Motion compensation ("un-blurring") of a lidar scan (seed 000 §3.2,
//! Eq. 12).
//!
//! A point `z_i` acquired at `t_i ∈ [t^k, t^{k+1}]` on a target moving with
//! constant velocity `v` and constant angular velocity is moved to where it
//! would be at the scan end `t^{k+1}`. With `Δt_i = t^{k+1} - t_i`, `p` the
//! predicted target origin at the scan end and `R ω` the angular velocity in
//! the sensor frame:
//! `z_i(t^{k+1}) = p + Exp(R ω Δt_i) (z_i(t_i) - p + v Δt_i)` (Eq. 12).
//!
//! Derivation (why it is exact for the constant-velocity model of Eq. 8-9):
//! `z_i = R(t_i) b + p(t_i)` for a body point `b`; `R(t^{k+1}) = R(t_i)
//! Exp(ω Δt_i) = Exp(R(t_i) ω Δt_i) R(t_i)`, and `R(t) ω` is constant
//! because `Exp(ω s) ω = ω`; `p(t_i) = p - v Δt_i`. Hence
//! `R(t^{k+1}) b + p = Exp(R ω Δt_i)(z_i - p + v Δt_i) + p`.
//!
//! Timestamps: every compensated point gets `t = t^{k+1}`, the time its new
//! coordinates refer to. Continuous-time registration (CT-NDT) needs the
//! original timestamps, so it must be given the *uncompensated* cloud.
//! Any finite timestamp is accepted (Eq. 12 extrapolates both ways), but the
//! model error grows with `|Δt_i|`: pass scans, not histories.

use crate::error::FilterError;
use crate::filter::Prediction;
use nalgebra::Vector3;
use spacepose_geometry::Point;

/// The constant-velocity motion of the target used to un-blur one scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionCompensation {
    /// Scan end `t^{k+1}` (s, sensor clock): the time points are moved to.
    pub t_end: f64,
    /// Target origin at `t_end`, sensor frame (m).
    pub p_sensor: Vector3<f64>,
    /// Target velocity, sensor frame (m/s).
    pub v_sensor: Vector3<f64>,
    /// Target angular velocity in the sensor frame, `R ω` (rad/s).
    pub w_sensor: Vector3<f64>,
}

impl MotionCompensation {
    /// From explicit values. Fails on non-finite input.
    pub fn new(
        t_end: f64,
        p_sensor: Vector3<f64>,
        v_sensor: Vector3<f64>,
        w_sensor: Vector3<f64>,
    ) -> Result<Self, FilterError> {
        let finite = t_end.is_finite()
            && p_sensor
                .iter()
                .chain(v_sensor.iter())
                .chain(w_sensor.iter())
                .all(|v| v.is_finite());
        if !finite {
            return Err(FilterError::NonFinite {
                what: "motion-compensation model",
            });
        }
        Ok(Self {
            t_end,
            p_sensor,
            v_sensor,
            w_sensor,
        })
    }

    /// From the filter's prediction at the scan end (`prediction.t = t^{k+1}`).
    pub fn from_prediction(prediction: &Prediction) -> Result<Self, FilterError> {
        Self::new(
            prediction.t,
            prediction.pose.translation,
            prediction.v_sensor,
            prediction.w_sensor(),
        )
    }

    /// Eq. (12) for one position `z` acquired at time `t`, in double precision.
    #[inline]
    pub fn position_at_end(&self, z: &Vector3<f64>, t: f64) -> Vector3<f64> {
        self.position_with(&FixedAxis::new(&self.w_sensor), z, t)
    }

    /// Eq. (12) with the rotation axis precomputed.
    #[inline]
    fn position_with(&self, axis: &FixedAxis, z: &Vector3<f64>, t: f64) -> Vector3<f64> {
        let dt = self.t_end - t;
        self.p_sensor + axis.rotate(&(z - self.p_sensor + self.v_sensor * dt), dt)
    }

    /// The compensated copy of `points`: positions at `t_end`, intensity
    /// kept, `t` set to `t_end`. Fails on the first non-finite point.
    pub fn compensate(&self, points: &[Point]) -> Result<Vec<Point>, FilterError> {
        check_points(points)?;
        let axis = FixedAxis::new(&self.w_sensor);
        Ok(points
            .iter()
            .map(|p| self.compensate_point(&axis, p))
            .collect())
    }

    /// [`Self::compensate`] in place. On error the slice is left untouched.
    pub fn compensate_in_place(&self, points: &mut [Point]) -> Result<(), FilterError> {
        check_points(points)?;
        let axis = FixedAxis::new(&self.w_sensor);
        for p in points.iter_mut() {
            *p = self.compensate_point(&axis, p);
        }
        Ok(())
    }

    fn compensate_point(&self, axis: &FixedAxis, p: &Point) -> Point {
        Point::from_vector(
            &self.position_with(axis, &p.position(), p.t),
            p.intensity,
            self.t_end,
        )
    }
}

/// `Exp(w Δt)` of Eq. (12) for a fixed `w`: the rotation is about the fixed
/// unit axis `n = w / |w|` by `θ = |w| Δt`, so Rodrigues' formula
/// `Exp(θ n) v = v cos θ + (n × v) sin θ + n (n·v)(1 - cos θ)` costs one
/// `sin_cos` per point instead of a full `so3::exp` (Eq. 4).
struct FixedAxis {
    /// Unit axis (zero when `w = 0`, which makes the rotation the identity).
    axis: Vector3<f64>,
    /// `|w|` (rad/s).
    rate: f64,
}

impl FixedAxis {
    fn new(w: &Vector3<f64>) -> Self {
        let rate = w.norm();
        let axis = if rate > 0.0 {
            w / rate
        } else {
            Vector3::zeros()
        };
        Self { axis, rate }
    }

    #[inline]
    fn rotate(&self, v: &Vector3<f64>, dt: f64) -> Vector3<f64> {
        let (s, c) = (self.rate * dt).sin_cos();
        let n = &self.axis;
        v * c + n.cross(v) * s + n * (n.dot(v) * (1.0 - c))
    }
}

fn check_points(points: &[Point]) -> Result<(), FilterError> {
    match points.iter().position(|p| !p.is_finite()) {
        Some(index) => Err(FilterError::NonFinitePoint { index }),
        None => Ok(()),
    }
}

#[cfg(test)]
#[path = "motion_compensation_tests.rs"]
mod tests;
