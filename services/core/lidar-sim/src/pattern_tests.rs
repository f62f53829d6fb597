use super::*;
use rand::SeedableRng;

fn off_axis_deg(d: &Vector3<f64>) -> f64 {
    d.z.clamp(-1.0, 1.0).acos().to_degrees()
}

#[test]
fn rosette_covers_a_38_4_degree_circle() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let scan = ScanPattern::livox_mid40().scan(1.0, 1.0, 100_000.0, &mut rng);
    assert_eq!(scan.len(), 100_000);
    let max = (0..scan.len())
        .map(|i| off_axis_deg(&scan.direction(i)))
        .fold(0.0, f64::max);
    assert!((max - 19.2).abs() < 0.05, "max off-axis {max}");
    // Coverage: 1° cells inside the circle of radius 18° are almost all hit in 1 s.
    let n = 40usize;
    let mut hit = vec![false; n * n];
    for i in 0..scan.len() {
        let d = scan.direction(i);
        let (x, y) = (d.x / d.z, d.y / d.z);
        let cx = ((x.atan().to_degrees() + 20.0) as usize).min(n - 1);
        let cy = ((y.atan().to_degrees() + 20.0) as usize).min(n - 1);
        hit[cy * n + cx] = true;
    }
    let (mut inside, mut covered) = (0, 0);
    for cy in 0..n {
        for cx in 0..n {
            let (x, y) = (cx as f64 - 19.5, cy as f64 - 19.5);
            if (x * x + y * y).sqrt() < 17.0 {
                inside += 1;
                covered += hit[cy * n + cx] as usize;
            }
        }
    }
    let frac = covered as f64 / inside as f64;
    assert!(frac > 0.95, "coverage {frac}");
}

#[test]
fn rosette_is_denser_in_the_centre() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let scan = ScanPattern::livox_mid40().scan(1.0, 0.5, 100_000.0, &mut rng);
    let (mut inner, mut ring) = (0.0, 0.0);
    for i in 0..scan.len() {
        let th = off_axis_deg(&scan.direction(i));
        if th < 4.0 {
            inner += 1.0;
        } else if (10.0..14.0).contains(&th) {
            ring += 1.0;
        }
    }
    // Per unit solid angle (small-angle areas: π r²).
    let inner_density = inner / (16.0);
    let ring_density = ring / (14.0f64.powi(2) - 10.0f64.powi(2));
    assert!(
        inner_density > 1.5 * ring_density,
        "{inner_density} vs {ring_density}"
    );
}

#[test]
fn consecutive_rosette_windows_differ() {
    let p = ScanPattern::livox_mid40();
    let t = 0.1;
    let a = Scan::new(p.clone(), t, t, 100_000.0, [0.3, 1.1], 0.0);
    let b = Scan::new(p, 2.0 * t, t, 100_000.0, [0.3, 1.1], t);
    assert_eq!(a.len(), b.len());
    // Same ray index, different direction for most rays.
    let differ = (0..a.len())
        .filter(|&i| (a.direction(i) - b.direction(i)).norm() > 1e-3)
        .count();
    assert!(differ as f64 > 0.99 * a.len() as f64, "{differ}");
    // And b is not a re-ordering of a: many rays of b are far from every ray of a.
    let step = 97;
    let far = (0..b.len())
        .step_by(step)
        .filter(|&j| {
            let dj = b.direction(j);
            (0..a.len()).all(|i| (a.direction(i) - dj).norm() > 2e-4)
        })
        .count();
    assert!(far > b.len() / step / 2, "{far}");
}

#[test]
fn timestamps_fill_the_window_in_order() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let scan = ScanPattern::livox_mid40().scan(5.0, 0.25, 100_000.0, &mut rng);
    assert!((scan.scan_start() - 4.75).abs() < 1e-12);
    assert!((scan.scan_end() - 5.0).abs() < 1e-9);
    let mut last = f64::NEG_INFINITY;
    for i in 0..scan.len() {
        let t = scan.time(i);
        assert!(t >= scan.scan_start() && t <= scan.scan_end() && t >= last);
        last = t;
    }
}

#[test]
fn ray_iterator_matches_random_access() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for pattern in [ScanPattern::livox_mid40(), ScanPattern::raster_seed002()] {
        let scan = pattern.scan(3.0, 0.72, 100_000.0, &mut rng);
        let mut n = 0;
        for (i, (t, d)) in scan.rays().enumerate() {
            assert_eq!(t, scan.time(i));
            assert!((d - scan.direction(i)).norm() < 1e-12, "ray {i}");
            n += 1;
        }
        assert_eq!(n, scan.len());
    }
}

#[test]
fn raster_is_41_by_41_at_one_degree() {
    let p = ScanPattern::raster_seed002();
    assert_eq!(p.raster_grid(), Some((41, 41)));
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let scan = p.scan(1.0, 1.0, 1681.0, &mut rng);
    assert_eq!(scan.len(), 1681);
    let first = scan.direction(0);
    let last = scan.direction(1680);
    assert!((first.x.atan2(first.z).to_degrees() + 20.0).abs() < 1e-9);
    assert!((last.x.atan2(last.z).to_degrees() - 20.0).abs() < 1e-9);
    assert!((last.y.asin().to_degrees() - 20.0).abs() < 1e-9);
    // Neighbouring columns are 1° apart on the centre row.
    let c = scan.direction(20 * 41 + 20);
    let r = scan.direction(20 * 41 + 21);
    assert!((c.angle(&r).to_degrees() - 1.0).abs() < 1e-9);
    assert!((c - Vector3::z()).norm() < 1e-12);
}
