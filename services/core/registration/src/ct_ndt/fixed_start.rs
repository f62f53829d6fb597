//! Continuous-time smoothed NDT with the start pose fixed, seed 000 §3.3:
//! the end pose `T^e` of a scan is optimised with `T^s` fixed (Eq. 14).

use super::interpolation::{Interpolation, ScanTimes};
use crate::degeneracy::constrained_directions;
use crate::error::RegistrationError;
use crate::gauss_newton;
use crate::ndt_map::NdtMap;
use crate::normal_equations::NormalEquations;
use crate::params::NdtParams;
use crate::result::Registration;
use crate::source::{check_pose, position_is_finite};
use nalgebra::Vector3;
use spacepose_geometry::{Point, Pose};

/// Normal equations of Eq. (14) at end pose `end`, every `stride`-th point.
fn linearise(
    map: &NdtMap,
    points: &[(Vector3<f64>, f64)],
    start: &Pose,
    end: &Pose,
    stride: usize,
    params: &NdtParams,
) -> NormalEquations {
    let interp = Interpolation::new(start, end);
    let mut ne = NormalEquations::new();
    // `points` holds `(R^s z, u)`.
    for (w, u) in points.iter().step_by(stride.max(1)) {
        let l = interp.apply(w, *u);
        if let Some((k, _)) = map.nearest_cell(&l.point, params.max_distance_m, params.lookup) {
            let (mean, information) = map.mean_and_information(k);
            ne.add_general(&l.j_r, &l.j_t, information, &(l.point - mean));
        }
    }
    ne
}

/// Continuous-time NDT: registers a scan whose points carry timestamps
/// within `scan`, optimising the end pose `T^e = t_target_sensor` at
/// `scan.end_s` with the start pose `t_target_sensor_start` (at
/// `scan.start_s`, typically the previous result) fixed (Eq. 14).
///
/// Same loop, termination and result as [`crate::register_ndt`]; the
/// returned pose and information refer to `T^e`. Points whose position or
/// timestamp is not finite are skipped and counted. Timestamps outside the
/// interval extrapolate the constant-velocity motion.
///
/// Errors: those of [`crate::register_ndt`], plus an invalid `scan` or a
/// non-finite start pose.
pub fn register_ct_ndt(
    map: &NdtMap,
    source: &[Point],
    scan: &ScanTimes,
    t_target_sensor_start: &Pose,
    initial_t_target_sensor_end: &Pose,
    params: &NdtParams,
) -> Result<Registration, RegistrationError> {
    params.validate()?;
    scan.validate()?;
    check_pose("t_target_sensor_start", t_target_sensor_start)?;
    check_pose("initial_t_target_sensor_end", initial_t_target_sensor_end)?;
    if source.is_empty() {
        return Err(RegistrationError::EmptyCloud);
    }
    let points: Vec<(Vector3<f64>, f64)> = source
        .iter()
        .filter(|p| position_is_finite(p) && p.t.is_finite())
        // Precomputed `w = R^s z`, fixed through the iterations.
        .map(|p| {
            (
                t_target_sensor_start.rotation * p.position(),
                scan.factor(p.t),
            )
        })
        .collect();
    if points.is_empty() {
        return Err(RegistrationError::AllPointsNonFinite {
            count: source.len(),
        });
    }
    let skipped = source.len() - points.len();
    let constrained = constrained_directions(map, source, initial_t_target_sensor_end, params);
    gauss_newton::run(
        *initial_t_target_sensor_end,
        params,
        points.len(),
        skipped,
        constrained.as_ref(),
        |end, stride| linearise(map, &points, t_target_sensor_start, end, stride, params),
    )
}
