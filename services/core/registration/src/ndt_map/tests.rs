use super::*;
use crate::test_support::{map, rng, target};
use nalgebra::SymmetricEigen;
use rand::RngExt;

#[test]
fn map_cells_are_finite_positive_definite_and_smoothed() {
    let map = map();
    let stats = map.stats();
    assert_eq!(stats.model_points, target().surface.len());
    // ~100k points on ~11 m² of surface in cells of at most 7.5 cm.
    assert!((1_000..40_000).contains(&stats.cells), "{stats:?}");
    assert!(
        stats.lookup_mean_candidates >= 1.0 && stats.lookup_mean_candidates < 40.0,
        "{stats:?}"
    );
    let floor = map.params().eigen_floor_abs_m.powi(2);
    for k in 0..map.len() {
        let c = map.cell(k).unwrap();
        assert!(c.points >= 1);
        let eig = SymmetricEigen::new(c.covariance).eigenvalues;
        assert!(eig.min() >= floor * (1.0 - 1e-9), "cell {k}: {eig}");
        assert!((c.covariance * c.inv_covariance - Matrix3::identity()).norm() < 1e-6);
    }
    assert!(map.cell(map.len()).is_none());
}

#[test]
fn smoothing_widens_cells_beyond_their_own_extent() {
    // A smoothed cell aggregates neighbours within 3σ: its largest standard
    // deviation exceeds that of a uniform 7.5 cm cell (7.5/√12 ≈ 2.2 cm).
    let map = map();
    let wide = (0..map.len())
        .filter(|&k| {
            let eig = SymmetricEigen::new(map.cell(k).unwrap().covariance).eigenvalues;
            eig.max().sqrt() > 0.03
        })
        .count();
    assert!(wide * 2 > map.len(), "{wide} of {}", map.len());
}

#[test]
fn grid_lookup_agrees_with_the_kd_tree() {
    let map = map();
    let mut rng = rng(7);
    let model = target().model();
    let mut hits = 0;
    for i in 0..20_000 {
        // Queries around the surface, and some anywhere in a wide box.
        let q = if i % 4 == 0 {
            Vector3::new(
                rng.random_range(-1.5..3.5),
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
            )
        } else {
            let m = model[rng.random_range(0..model.len())];
            m + Vector3::new(
                rng.random_range(-0.1..0.1),
                rng.random_range(-0.1..0.1),
                rng.random_range(-0.1..0.1),
            )
        };
        for d in [0.03, 0.075] {
            let grid = map.nearest_cell(&q, d, CellLookup::Grid);
            let tree = map.nearest_cell(&q, d, CellLookup::KdTree);
            match (grid, tree) {
                (Some((kg, dg)), Some((kt, dt))) => {
                    assert!((dg - dt).abs() < 1e-15, "{q}: {kg} {dg} vs {kt} {dt}");
                    hits += 1;
                }
                (None, None) => {}
                other => panic!("{q} at {d}: {other:?}"),
            }
        }
    }
    assert!(hits > 10_000, "{hits}");
    // Beyond the grid's distance the kd-tree answers.
    let far = map.means()[0] + Vector3::new(0.0, 0.0, 0.5);
    assert!(map.nearest_cell(&far, 1.0, CellLookup::Grid).is_some());
    assert!(
        map.nearest_cell(&Vector3::repeat(f64::NAN), 0.075, CellLookup::Grid)
            .is_none()
    );
    assert!(
        map.nearest_cell(&Vector3::repeat(f64::NAN), 1.0, CellLookup::KdTree)
            .is_none()
    );
}

#[test]
fn save_load_round_trip() {
    let map = map();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("target.ndtmap");
    map.save(&path).unwrap();
    let loaded = NdtMap::load(&path).unwrap();
    assert_eq!(loaded.len(), map.len());
    assert_eq!(loaded.params(), map.params());
    assert_eq!(loaded.stats(), map.stats());
    for k in (0..map.len()).step_by(13) {
        assert_eq!(loaded.cell(k), map.cell(k));
    }
    let q = map.means()[5] + Vector3::new(0.01, -0.02, 0.005);
    assert_eq!(
        loaded.nearest_cell(&q, 0.075, CellLookup::Grid),
        map.nearest_cell(&q, 0.075, CellLookup::Grid)
    );
}

#[test]
fn corrupt_or_foreign_files_are_errors() {
    let bytes = map().to_bytes().unwrap();
    // A flipped payload byte fails the checksum.
    let mut flipped = bytes.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 0x40;
    assert!(matches!(
        NdtMap::from_bytes(&flipped),
        Err(RegistrationError::MapCorrupt { .. })
    ));
    // Truncation.
    assert!(matches!(
        NdtMap::from_bytes(&bytes[..bytes.len() - 10]),
        Err(RegistrationError::MapCorrupt { .. })
    ));
    assert!(matches!(
        NdtMap::from_bytes(&bytes[..14]),
        Err(RegistrationError::MapCorrupt { .. })
    ));
    // Another version.
    let mut version = bytes.clone();
    version[8] = 99;
    assert!(matches!(
        NdtMap::from_bytes(&version),
        Err(RegistrationError::MapVersion {
            found: 99,
            expected: MAP_FORMAT_VERSION,
            ..
        })
    ));
    // Not a map at all.
    assert!(matches!(
        NdtMap::from_bytes(b"hello"),
        Err(RegistrationError::MapBadMagic { .. })
    ));
    // Missing file.
    let dir = tempfile::tempdir().unwrap();
    assert!(matches!(
        NdtMap::load(dir.path().join("missing.ndtmap")),
        Err(RegistrationError::MapIo { .. })
    ));
}

#[test]
fn invalid_models_and_parameters_are_errors() {
    let p = NdtMapParams::default();
    assert!(matches!(
        NdtMap::build(&[], &p),
        Err(RegistrationError::InvalidModel(_))
    ));
    let mut pts: Vec<Vector3<f64>> = (0..50)
        .map(|i| Vector3::new(i as f64 * 0.01, 0.0, 1.0))
        .collect();
    pts[7].y = f64::NAN;
    assert!(matches!(
        NdtMap::build(&pts, &p),
        Err(RegistrationError::InvalidModel(_))
    ));
    pts[7].y = 0.0;
    let bad = NdtMapParams {
        smoothing_sigma_m: f64::NAN,
        ..p
    };
    assert!(matches!(
        NdtMap::build(&pts, &bad),
        Err(RegistrationError::InvalidParameter { .. })
    ));
    // A degenerate but finite model (points on a line) builds: every cell
    // is regularised.
    let line = NdtMap::build(&pts, &p).unwrap();
    assert!(!line.is_empty());
}
