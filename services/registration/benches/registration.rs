//! Registration benchmarks on the synthetic spacecraft fixture (one
//! thread): map build and load, NDT (grid and kd-tree lookups), CT-NDT on a
//! blurred frame, and ICP. The lead will switch the fixture to a simulated
//! frame once the simulator lands.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use spacepose_geometry::{Pose, so3};
use spacepose_registration::synthetic::SyntheticTarget;
use spacepose_registration::{
    CellLookup, IcpModel, IcpParams, NdtMap, NdtMapParams, NdtParams, ScanTimes, register_ct_ndt,
    register_icp, register_ndt,
};
use std::hint::black_box;

/// The target rotated by `angle_deg` about a fixed oblique axis through its
/// centre of mass and shifted by `dist_m`: a tracking-sized initial error.
fn offset(truth: &Pose, angle_deg: f64, dist_m: f64) -> Pose {
    let axis = Vector3::new(0.3, -0.8, 0.5).normalize();
    let dir = Vector3::new(-0.6, 0.2, 0.77).normalize();
    Pose::new(so3::exp(&(axis * angle_deg.to_radians())), dir * dist_m).compose(truth)
}

fn benches(c: &mut Criterion) {
    let target = SyntheticTarget::spacecraft(0.01);
    let model = target.model();
    let t_sensor_target = Pose::new(
        so3::exp(&Vector3::new(0.5, -0.7, 0.3)),
        Vector3::new(0.15, -0.1, 6.0),
    );
    let truth = t_sensor_target.inverse();
    let frame = target.frame(&t_sensor_target, 0.02);
    let map_params = NdtMapParams::default();
    let map = NdtMap::build(&model, &map_params).expect("map");
    let bytes = map.to_bytes().expect("encode");
    eprintln!(
        "fixture: {} model points, {} frame points, {:?}, map file {} kB",
        model.len(),
        frame.len(),
        map.stats(),
        bytes.len() / 1024
    );

    let mut g = c.benchmark_group("map");
    g.sample_size(10);
    g.bench_function("build", |b| {
        b.iter(|| NdtMap::build(black_box(&model), &map_params))
    });
    g.bench_function("load_from_bytes", |b| {
        b.iter(|| NdtMap::from_bytes(black_box(&bytes)))
    });
    g.finish();

    let initial = offset(&truth, 2.0, 0.03);
    let grid = NdtParams::default();
    let tree = NdtParams {
        lookup: CellLookup::KdTree,
        ..grid
    };
    for (name, p) in [("grid", grid), ("kdtree", tree)] {
        let r = register_ndt(&map, &frame, &initial, &p).expect("ndt");
        let (a, d) = r.t_target_sensor.error_to(&truth);
        eprintln!(
            "ndt/{name}: {} it, converged {}, error {:.3}° {:.2} mm",
            r.iterations,
            r.converged,
            a.to_degrees(),
            d * 1e3
        );
    }
    let mut g = c.benchmark_group("ndt");
    g.bench_function("grid_2deg_3cm", |b| {
        b.iter(|| register_ndt(&map, black_box(&frame), &initial, &grid))
    });
    g.bench_function("kdtree_2deg_3cm", |b| {
        b.iter(|| register_ndt(&map, black_box(&frame), &initial, &tree))
    });
    g.finish();

    // CT-NDT: a 6° / 4 cm tumble during the scan, start pose known, end-pose
    // guess 2° / 3 cm off.
    let end = offset(&truth, 6.0, 0.04);
    let scan = ScanTimes {
        start_s: 0.0,
        end_s: 1.0,
    };
    let blurred = target.blurred_frame(&truth, &end, scan.start_s, scan.end_s, 0.02);
    let guess = offset(&end, 2.0, 0.03);
    let r = register_ct_ndt(&map, &blurred, &scan, &truth, &guess, &grid).expect("ct-ndt");
    let (a, d) = r.t_target_sensor.error_to(&end);
    eprintln!(
        "ct_ndt: {} points, {} it, converged {}, end error {:.3}° {:.2} mm",
        blurred.len(),
        r.iterations,
        r.converged,
        a.to_degrees(),
        d * 1e3
    );
    let mut g = c.benchmark_group("ct_ndt");
    g.bench_function("grid_6deg_blur", |b| {
        b.iter(|| register_ct_ndt(&map, black_box(&blurred), &scan, &truth, &guess, &grid))
    });
    g.finish();

    let icp_model = IcpModel::new(&model).expect("icp model");
    let icp = IcpParams::default();
    let r = register_icp(&icp_model, &frame, &initial, &icp).expect("icp");
    let (a, d) = r.t_target_sensor.error_to(&truth);
    eprintln!(
        "icp: {} it, converged {}, error {:.3}° {:.2} mm, f_CONV {:.2} mm²",
        r.iterations,
        r.converged,
        a.to_degrees(),
        d * 1e3,
        r.f_conv_m2.unwrap_or(f64::NAN) * 1e6
    );
    let mut g = c.benchmark_group("icp");
    g.sample_size(10);
    g.bench_function("2deg_3cm", |b| {
        b.iter(|| register_icp(&icp_model, black_box(&frame), &initial, &icp))
    });
    g.bench_function("model_build", |b| {
        b.iter(|| IcpModel::new(black_box(&model)))
    });
    g.finish();
}

criterion_group!(registration, benches);
criterion_main!(registration);
