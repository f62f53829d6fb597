//! The attitude grid of seed 002 §2.1: 321 Euler angles with step Δ over
//! ]−180°, 180°[ (yaw) × ]−90°, 90°[ (pitch) × ]−180°, 180°[ (roll), the
//! boundaries left out to avoid ambiguous triplets.

use crate::error::AcquisitionError;
use spacepose_geometry::Euler321;

/// The multiples `k Δ` strictly inside `]−half, half[` (degrees), ascending.
pub fn open_axis_deg(delta_deg: f64, half_deg: f64) -> Vec<f64> {
    // A tolerance so that 180 = 6 x 30 is recognised as the boundary.
    let eps = 1e-9 * half_deg;
    let k_max = ((half_deg - eps) / delta_deg).floor() as i64;
    (-k_max..=k_max).map(|k| k as f64 * delta_deg).collect()
}

/// Every grid triplet (yaw outermost, roll innermost).
///
/// Errors: Δ not finite or outside ]0°, 90°].
pub fn euler_grid(delta_deg: f64) -> Result<Vec<Euler321>, AcquisitionError> {
    if !(delta_deg.is_finite() && delta_deg > 0.0 && delta_deg <= 90.0) {
        return Err(AcquisitionError::InvalidConfig {
            field: "delta_deg",
            value: delta_deg,
            reason: "must be in ]0, 90] degrees",
        });
    }
    let yaw = open_axis_deg(delta_deg, 180.0);
    let pitch = open_axis_deg(delta_deg, 90.0);
    let roll = yaw.clone();
    let mut grid = Vec::with_capacity(yaw.len() * pitch.len() * roll.len());
    for &y in &yaw {
        for &p in &pitch {
            for &r in &roll {
                grid.push(Euler321::from_degrees(y, p, r));
            }
        }
    }
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delta_30_gives_11_5_11_without_boundaries() {
        assert_eq!(open_axis_deg(30.0, 180.0).len(), 11);
        assert_eq!(
            open_axis_deg(30.0, 90.0),
            vec![-60.0, -30.0, 0.0, 30.0, 60.0]
        );
        let g = euler_grid(30.0).unwrap();
        assert_eq!(g.len(), 11 * 5 * 11);
        for e in &g {
            let [y, p, r] = e.to_degrees();
            assert!(
                y.abs() < 179.0 && p.abs() < 89.0 && r.abs() < 179.0,
                "{y} {p} {r}"
            );
        }
    }

    #[test]
    fn other_steps_and_bad_steps() {
        assert_eq!(euler_grid(60.0).unwrap().len(), 5 * 3 * 5);
        assert_eq!(euler_grid(40.0).unwrap().len(), 9 * 5 * 9);
        assert_eq!(euler_grid(10.0).unwrap().len(), 35 * 17 * 35);
        for bad in [0.0, -5.0, f64::NAN, 120.0] {
            assert!(euler_grid(bad).is_err());
        }
    }
}
