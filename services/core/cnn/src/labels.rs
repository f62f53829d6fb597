//! Soft attitude labels with symmetries, `L_sym` of seed 004 Eq. (15) (Eq. 9
//! with `d_sym` of Eq. 14 in place of `d`): `l_i = K exp(−d_sym(R, R_i)² / 2σ²)`,
//! `Σ l_i = 1`, σ = 2Δα/3.

use nalgebra::Rotation3;
use spacepose_geometry::so3;

use crate::classes::ClassTable;

/// The soft label vector `L_sym(r)` (length m), summing to 1.
pub fn soft_labels(classes: &ClassTable, r: &Rotation3<f64>) -> Vec<f32> {
    let mut out = vec![0.0; classes.len()];
    soft_labels_into(classes, r, &mut out);
    out
}

/// [`soft_labels`] into a caller-owned slice of length m (extra entries untouched).
pub fn soft_labels_into(classes: &ClassTable, r: &Rotation3<f64>, out: &mut [f32]) {
    let two_sigma2 = 2.0 * classes.sigma_rad().powi(2);
    let d2: Vec<f64> = classes
        .rotations()
        .iter()
        .map(|ri| so3::distance_sym(r, ri, classes.symmetries()).powi(2))
        .collect();
    // Shift by the smallest distance before exp (K absorbs it): no underflow.
    let d2_min = d2.iter().copied().fold(f64::INFINITY, f64::min);
    let w: Vec<f64> = d2
        .iter()
        .map(|d| (-(d - d2_min) / two_sigma2).exp())
        .collect();
    let k = 1.0 / w.iter().sum::<f64>();
    for (o, wi) in out.iter_mut().zip(&w) {
        *o = (wi * k) as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classes::DEFAULT_ROLL_STEP_DEG;
    use nalgebra::UnitQuaternion;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use spacepose_model::Target;

    pub(crate) fn random_rotation(rng: &mut ChaCha8Rng) -> Rotation3<f64> {
        use rand_distr::{Distribution, StandardNormal};
        let v: [f64; 4] = std::array::from_fn(|_| StandardNormal.sample(rng));
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(v[0], v[1], v[2], v[3]))
            .to_rotation_matrix()
    }

    #[test]
    fn labels_sum_to_one_and_peak_at_the_nearest_class() {
        let deos = Target::builtin("deos").unwrap();
        let table = ClassTable::for_target(&deos, DEFAULT_ROLL_STEP_DEG).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..20 {
            let r = random_rotation(&mut rng);
            let l = soft_labels(&table, &r);
            let sum: f64 = l.iter().map(|&v| f64::from(v)).sum();
            assert!((sum - 1.0).abs() < 1e-5, "sum {sum}");
            assert!(l.iter().all(|&v| v >= 0.0));
            let argmax = (0..l.len()).max_by(|&a, &b| l[a].total_cmp(&l[b])).unwrap();
            let nearest = (0..table.len())
                .min_by(|&a, &b| {
                    let da = so3::distance_sym(&r, &table.rotations()[a], deos.symmetries());
                    let db = so3::distance_sym(&r, &table.rotations()[b], deos.symmetries());
                    da.total_cmp(&db)
                })
                .unwrap();
            assert_eq!(argmax, nearest);
        }
    }

    #[test]
    fn a_class_attitude_peaks_at_its_own_class_and_symmetric_copies_agree() {
        let deos = Target::builtin("deos").unwrap();
        let table = ClassTable::for_target(&deos, DEFAULT_ROLL_STEP_DEG).unwrap();
        for i in [0, 17, 300, table.len() - 1] {
            let r = table.rotations()[i];
            let l = soft_labels(&table, &r);
            let argmax = (0..l.len()).max_by(|&a, &b| l[a].total_cmp(&l[b])).unwrap();
            assert_eq!(argmax, i);
            // L_sym is invariant under the symmetries: R S_k gives the same vector.
            for s in deos.symmetries() {
                let l2 = soft_labels(&table, &(r * s));
                let max_diff = l
                    .iter()
                    .zip(&l2)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f32::max);
                assert!(max_diff < 1e-5, "{max_diff}");
            }
        }
    }
}
