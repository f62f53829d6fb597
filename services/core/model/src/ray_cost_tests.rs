//! Measured cost of one ray cast on the built-in targets (run with `--nocapture` to see it).

use std::time::Instant;

use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::Target;

/// Rays from a sensor `range_m` away on an oblique line of sight, aimed at random points of a disc of radius
/// `aim_radius_m` around the body origin (perpendicular to the line of sight). Returns
/// (ns per ray, hit fraction).
fn time_rays(t: &Target, range_m: f64, aim_radius_m: f64, n: usize) -> (f64, f64) {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    // A slightly oblique line of sight so no face is seen exactly edge-on.
    let sensor = Vector3::new(0.31, -0.44, 0.84).normalize() * range_m;
    let los = -sensor.normalize();
    let e1 = los.cross(&Vector3::x()).normalize();
    let e2 = los.cross(&e1);
    let dirs: Vec<Vector3<f64>> = (0..n)
        .map(|_| {
            let (a, b) = loop {
                let a: f64 = rng.random_range(-1.0..1.0);
                let b: f64 = rng.random_range(-1.0..1.0);
                if a * a + b * b <= 1.0 {
                    break (a, b);
                }
            };
            (e1 * a * aim_radius_m + e2 * b * aim_radius_m - sensor).normalize()
        })
        .collect();
    let start = Instant::now();
    let mut hits = 0usize;
    for d in &dirs {
        if let Some(h) = t.cast_ray(&sensor, d, 2.0 * range_m) {
            hits += 1;
            std::hint::black_box(h);
        }
    }
    let ns = start.elapsed().as_nanos() as f64 / n as f64;
    (ns, hits as f64 / n as f64)
}

#[test]
fn ray_cast_cost_on_builtin_targets() {
    let n = 300_000;
    for (name, range) in [("deos", 10.0), ("envisat", 60.0)] {
        let t = Target::builtin(name).unwrap();
        let r = t.bounding_radius();
        let tris = t.mesh().triangle_count();
        // Aimed inside the bounding circle: mostly hits (worst case).
        let (ns_in, hit_in) = time_rays(&t, range, 0.5 * r, n);
        // A field of view 3x the target: most rays rejected by the bounding sphere.
        let (ns_wide, hit_wide) = time_rays(&t, range, 3.0 * r, n);
        println!(
            "{name} ({tris} triangles): {ns_in:.0} ns/ray aimed at the target ({:.0}% hits), \
             {ns_wide:.0} ns/ray over a 3x wider field ({:.0}% hits)",
            100.0 * hit_in,
            100.0 * hit_wide
        );
        assert!(hit_in > 0.2 && hit_wide < hit_in);
        // Loose bound (shared 2-core machine); the target is ~670 ns (1.5 M rays/s).
        assert!(ns_in < 5000.0, "{name}: {ns_in} ns per ray");
    }
}
