//! The acquisition methods tried in order on one frame: the first accepted
//! pose wins; when none is accepted the frame's acquisition failed.

use crate::error::InitError;
use crate::method::{Attempt, PoseAcquirer};
use spacepose_geometry::{Point, voxel_filter};
use spacepose_messages::AcquisitionMethod;
use std::time::Instant;

/// The result of acquiring on one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Acquisition {
    /// Every attempt, in the order tried (it stops at the first accepted).
    pub attempts: Vec<Attempt>,
    /// Finite points of the frame.
    pub points: usize,
    /// The chain's first method (reported when none was tried).
    pub first_method: AcquisitionMethod,
    /// Why no method was tried (too few finite points: no target in view),
    /// if none was.
    pub skipped: Option<String>,
    /// Wall time of the whole acquisition (ms).
    pub time_ms: f64,
}

impl Acquisition {
    /// The accepted attempt, if any.
    pub fn accepted(&self) -> Option<&Attempt> {
        self.attempts.iter().find(|a| a.accepted())
    }

    /// The attempt to report: the accepted one, else the output with the
    /// lowest f_CONV, else the last attempt.
    pub fn reported(&self) -> Option<&Attempt> {
        self.accepted()
            .or_else(|| {
                self.attempts
                    .iter()
                    .filter(|a| a.f_conv_m2().is_some_and(f64::is_finite))
                    .min_by(|a, b| {
                        a.f_conv_m2()
                            .partial_cmp(&b.f_conv_m2())
                            .unwrap_or(std::cmp::Ordering::Equal)
                    })
            })
            .or(self.attempts.last())
    }

    /// One line for the log: each attempt's method, verdict, f_CONV and time.
    pub fn summary(&self) -> String {
        if let Some(reason) = &self.skipped {
            return format!("{} points: {reason}; no method tried", self.points);
        }
        let parts: Vec<String> = self
            .attempts
            .iter()
            .map(|a| match &a.outcome {
                Ok(o) => format!(
                    "{} {} f_conv={:.2e} m² in {:.0} ms ({})",
                    a.method.as_str(),
                    if o.accepted { "accepted" } else { "rejected" },
                    o.f_conv_m2,
                    a.time_ms,
                    o.detail
                ),
                Err(e) => format!("{} failed: {e}", a.method.as_str()),
            })
            .collect();
        format!("{} points: {}", self.points, parts.join("; "))
    }
}

/// The configured methods, tried in order.
pub struct MethodChain {
    methods: Vec<Box<dyn PoseAcquirer>>,
    min_points: usize,
    /// Voxel edge of the cloud the methods see (m); `None`: the points.
    voxel_leaf_m: Option<f64>,
}

impl MethodChain {
    /// `methods` in the order to try them; a frame with fewer than
    /// `min_points` finite points is a failure without trying any.
    pub fn new(methods: Vec<Box<dyn PoseAcquirer>>, min_points: usize) -> Result<Self, InitError> {
        if methods.is_empty() {
            return Err(InitError::InvalidConfig(
                "at least one acquisition method is needed".into(),
            ));
        }
        Ok(Self {
            methods,
            min_points,
            voxel_leaf_m: None,
        })
    }

    /// The chain with the frame voxel-filtered at `leaf_size_m` (m) before
    /// the methods see it (seed 000 §3.3's filter; 0: the points as they
    /// are). Ingest used to do this for every consumer; since the tracker
    /// compensates the raw points before its own voxel filter (the one
    /// frame path), acquisition does its own, so its input is unchanged.
    pub fn with_voxels(mut self, leaf_size_m: f64) -> Result<Self, InitError> {
        if !(leaf_size_m.is_finite() && leaf_size_m >= 0.0) {
            return Err(InitError::InvalidConfig(format!(
                "leaf_size_m = {leaf_size_m} must be finite and >= 0"
            )));
        }
        self.voxel_leaf_m = (leaf_size_m > 0.0).then_some(leaf_size_m);
        Ok(self)
    }

    /// The first method (the chain holds at least one).
    fn first_method(&self) -> AcquisitionMethod {
        self.methods
            .first()
            .map_or(AcquisitionMethod::TemplateMatching, |m| m.method())
    }

    /// The methods' kinds, in order.
    pub fn methods(&self) -> Vec<AcquisitionMethod> {
        self.methods.iter().map(|m| m.method()).collect()
    }

    /// Tries each method on the finite points of `cloud` until one is accepted.
    pub fn acquire(&self, cloud: &[Point]) -> Acquisition {
        let started = Instant::now();
        let finite: Vec<Point> = cloud.iter().copied().filter(Point::is_finite).collect();
        let points = finite.len();
        let finite = match self.voxel_leaf_m.map(|leaf| voxel_filter(&finite, leaf)) {
            None => finite,
            Some(Ok(v)) => v.points,
            Some(Err(e)) => {
                return Acquisition {
                    attempts: Vec::new(),
                    first_method: self.first_method(),
                    points,
                    skipped: Some(format!("voxel filter: {e}")),
                    time_ms: started.elapsed().as_secs_f64() * 1e3,
                };
            }
        };
        if finite.len() < self.min_points {
            // No target in view (an empty frame from ingest, or a few stray
            // points): no method can run, and none is blamed.
            return Acquisition {
                attempts: Vec::new(),
                first_method: self.first_method(),
                points,
                skipped: Some(format!(
                    "no target in view (too few points: {} used, {points} finite of {}, need {})",
                    finite.len(),
                    cloud.len(),
                    self.min_points
                )),
                time_ms: started.elapsed().as_secs_f64() * 1e3,
            };
        }
        let mut attempts = Vec::new();
        for m in &self.methods {
            let t0 = Instant::now();
            let outcome = m.acquire(&finite).and_then(|o| check_output(m.method(), o));
            let attempt = Attempt {
                method: m.method(),
                outcome,
                time_ms: t0.elapsed().as_secs_f64() * 1e3,
            };
            let done = attempt.accepted();
            attempts.push(attempt);
            if done {
                break;
            }
        }
        Acquisition {
            attempts,
            first_method: self.first_method(),
            points,
            skipped: None,
            time_ms: started.elapsed().as_secs_f64() * 1e3,
        }
    }
}

/// A method's output with a non-finite pose or f_CONV is never accepted.
fn check_output(
    method: AcquisitionMethod,
    o: crate::method::MethodOutput,
) -> Result<crate::method::MethodOutput, InitError> {
    if o.t_sensor_target.is_finite() && o.f_conv_m2.is_finite() {
        return Ok(o);
    }
    Err(InitError::Method {
        method: method.as_str(),
        reason: format!(
            "non-finite output (f_conv {}, pose finite: {})",
            o.f_conv_m2,
            o.t_sensor_target.is_finite()
        ),
    })
}

#[cfg(test)]
#[path = "chain_tests.rs"]
mod tests;
