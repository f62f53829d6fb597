//! Registration benchmarks on issue 3's fixture (one thread): a simulated
//! `deos` frame (Livox Mid-40 model, default effects) at 10 m, about 11k
//! points after the 2 cm voxel filter, against the model sampled every
//! 1.5 cm. Benches: map build and load, NDT including the voxel filter
//! (grid and kd-tree lookups), CT-NDT on the same view blurred by a 10°/s
//! tumble (voxel filter included), ICP (grid and kd-tree lookups, voxel
//! filter included).
//!
//! Before Criterion runs, every variant is also timed in interleaved rounds
//! and its median printed as a ratio against a baseline of the same run
//! (NDT with the grid), so the figures survive machine noise.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use spacepose_geometry::{Euler321, Point, Pose, VoxelFilter, so3};
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_model::Target;
use spacepose_registration::{
    CellLookup, CtPriors, DisplacementPrior, IcpModel, IcpParams, NdtMap, NdtMapParams, NdtParams,
    RatePrior, Registration, ScanTimes, StartPrior, register_ct_ndt, register_ct_ndt_free_start,
    register_ct_ndt_with_priors, register_icp, register_ndt,
};
use spacepose_scenario::TruthState;
use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

/// Integration time giving about 11,000 points after the 2 cm voxel filter
/// at this range and attitude (the count is printed).
const INTEGRATION_TIME_S: f64 = 0.78;
/// Scan end time on the sensor clock (s).
const T_END_S: f64 = 10.0;
/// Voxel filter leaf (Table 1).
const VOXEL_M: f64 = 0.02;

/// The pose rotated by `angle_deg` about a fixed oblique axis through the
/// target's centre of mass and shifted by `dist_m`: a tracking-sized
/// initial error, `(ΔR, Δp) ∘ T`.
fn offset(t_target_sensor: &Pose, angle_deg: f64, dist_m: f64) -> Pose {
    let axis = Vector3::new(0.3, -0.8, 0.5).normalize();
    let dir = Vector3::new(-0.6, 0.2, 0.77).normalize();
    Pose::new(so3::exp(&(axis * angle_deg.to_radians())), dir * dist_m).compose(t_target_sensor)
}

/// The frames and poses of the benchmarks.
struct Fixture {
    model: Vec<Vector3<f64>>,
    /// Static raw frame (no motion).
    raw: Vec<Point>,
    /// The same view with a 10°/s tumble during the scan.
    raw_blurred: Vec<Point>,
    /// True `t_target_sensor` of the static frame and of the blurred
    /// frame's scan end.
    truth: Pose,
    /// True `t_target_sensor` at the blurred frame's scan start.
    truth_start: Pose,
    scan: ScanTimes,
}

fn fixture() -> Fixture {
    let target = Arc::new(Target::builtin("deos").expect("deos"));
    let model = target.sample_surface(0.015, 0);
    let mut sensor = SensorConfig::livox_mid40();
    sensor.integration_time_s = INTEGRATION_TIME_S;
    let sim = LidarSimulator::new(target, sensor).expect("simulator");
    let t_sensor_target = Pose::new(
        Euler321::from_degrees(35.0, -20.0, 25.0).to_rotation(),
        Vector3::new(0.1, -0.05, 10.0),
    );
    let still = TruthState {
        t: T_END_S,
        t_sensor_target,
        v_sensor_target: Vector3::zeros(),
        w_target: Vector3::zeros(),
    };
    let raw = sim
        .simulate(&still, &mut LidarSimulator::frame_rng(3, 0))
        .points;
    // 10°/s about an oblique body axis; the target rotates as
    // R(t) = R(t_end) Exp(ω (t - t_end)) during the scan.
    let w_target = Vector3::new(0.2, 0.9, -0.4).normalize() * 10f64.to_radians();
    let tumbling = TruthState { w_target, ..still };
    let blurred = sim.simulate(&tumbling, &mut LidarSimulator::frame_rng(3, 1));
    let start = Pose::new(
        t_sensor_target.rotation * so3::exp(&(-w_target * INTEGRATION_TIME_S)),
        t_sensor_target.translation,
    );
    Fixture {
        model,
        raw,
        raw_blurred: blurred.points,
        truth: t_sensor_target.inverse(),
        truth_start: start.inverse(),
        scan: ScanTimes {
            start_s: blurred.scan_start,
            end_s: blurred.scan_end,
        },
    }
}

fn filtered(voxel: &mut VoxelFilter, raw: &[Point]) -> Vec<Point> {
    voxel.filter(raw).expect("voxel filter").points
}

/// Prints iterations and the error of `t_sensor_target` (position error in
/// the sensor frame, not the lever-armed one of `t_target_sensor`).
fn report(name: &str, r: &Registration, truth: &Pose) {
    let (a, d) = r.t_target_sensor.inverse().error_to(&truth.inverse());
    eprintln!(
        "{name}: {} it, converged {}, error {:.3}° {:.2} mm, {} inliers / {}",
        r.iterations,
        r.converged,
        a.to_degrees(),
        d * 1e3,
        r.inliers,
        r.valid_points
    );
}

fn median_ms(samples: &mut [f64]) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2] * 1e3
}

/// A named job of [`same_run_ratios`].
type Job<'a> = (&'static str, Box<dyn FnMut() + 'a>);

/// Times every job once per round, `rounds` times, interleaved; prints the
/// medians and their ratio to the first job's.
fn same_run_ratios(rounds: usize, jobs: &mut [Job<'_>]) {
    let mut samples = vec![Vec::with_capacity(rounds); jobs.len()];
    for _ in 0..rounds {
        for (k, (_, job)) in jobs.iter_mut().enumerate() {
            let t0 = Instant::now();
            job();
            samples[k].push(t0.elapsed().as_secs_f64());
        }
    }
    let medians: Vec<f64> = samples.iter_mut().map(|s| median_ms(s)).collect();
    eprintln!("same-run medians over {rounds} interleaved rounds:");
    for ((name, _), m) in jobs.iter().zip(&medians) {
        eprintln!(
            "  {name:<22} {m:8.2} ms   ×{:.2} of {}",
            m / medians[0],
            jobs[0].0
        );
    }
}

/// A diagonal information for standard deviations `rot_rad` and `pos_m`.
fn start_information(rot_rad: f64, pos_m: f64) -> nalgebra::Matrix6<f64> {
    let (a, b) = (1.0 / (rot_rad * rot_rad), 1.0 / (pos_m * pos_m));
    nalgebra::Matrix6::from_diagonal(&nalgebra::Vector6::new(a, a, a, b, b, b))
}

fn benches(c: &mut Criterion) {
    let f = fixture();
    let map_params = NdtMapParams::default();
    let map = NdtMap::build(&f.model, &map_params).expect("map");
    let bytes = map.to_bytes().expect("encode");
    let t0 = Instant::now();
    let icp_model = IcpModel::new(&f.model).expect("icp model");
    eprintln!(
        "icp model built in {:.0} ms: {:?}",
        t0.elapsed().as_secs_f64() * 1e3,
        icp_model.lookup_stats()
    );
    let mut voxel = VoxelFilter::new(VOXEL_M).expect("voxel");
    let frame = filtered(&mut voxel, &f.raw);
    let blurred = filtered(&mut voxel, &f.raw_blurred);
    eprintln!(
        "fixture: deos at 10 m, {} model points, raw frame {} points → {} after the \
         {VOXEL_M} m voxel filter; blurred frame {} → {}; {:?}; map file {} kB",
        f.model.len(),
        f.raw.len(),
        frame.len(),
        f.raw_blurred.len(),
        blurred.len(),
        map.stats(),
        bytes.len() / 1024
    );

    let initial = offset(&f.truth, 2.0, 0.03);
    let guess_end = initial;
    let grid = NdtParams::default();
    let tree = NdtParams {
        lookup: CellLookup::KdTree,
        ..grid
    };
    let icp = IcpParams::default();
    let icp_tree = IcpParams {
        lookup: CellLookup::KdTree,
        ..icp
    };
    let ndt_run = |voxel: &mut VoxelFilter, p: &NdtParams| {
        let cloud = filtered(voxel, &f.raw);
        register_ndt(&map, &cloud, &initial, p).expect("ndt")
    };
    let ct_run = |voxel: &mut VoxelFilter| {
        let cloud = filtered(voxel, &f.raw_blurred);
        register_ct_ndt(&map, &cloud, &f.scan, &f.truth_start, &guess_end, &grid).expect("ct")
    };
    // The tracker's default: the start pose free under a prior (σ 0.5°,
    // 1 cm, the order of the filter's posterior) 0.5° / 1 cm off the truth.
    let prior = StartPrior {
        t_target_sensor: offset(&f.truth_start, 0.5, 0.01),
        information: start_information(0.5f64.to_radians(), 0.01),
    };
    let ct_free_run = |voxel: &mut VoxelFilter| {
        let cloud = filtered(voxel, &f.raw_blurred);
        register_ct_ndt_free_start(&map, &cloud, &f.scan, &prior, &guess_end, &grid)
            .expect("ct free start")
            .end
    };
    // The tracker's default since the motion prior: the turn and
    // displacement over the scan 0.1° / 5 mm off the truth under σ 0.1° /
    // 5 mm (the filter's velocity errors over a 1 s scan), and no start
    // prior. As in the tracker, where both poses start at the filter's
    // predictions, the start pose's first guess is the end guess moved back
    // by the prior's motion (the start prior's mean, with no information).
    let true_turn = f.truth.rotation * f.truth_start.rotation.inverse();
    let origin = |p: &Pose| -(p.rotation.inverse() * p.translation);
    let (s_turn, s_disp) = (0.1f64.to_radians(), 0.005);
    let turn = so3::exp(&Vector3::new(0.0, s_turn, 0.0)) * true_turn;
    let displacement = origin(&f.truth) - origin(&f.truth_start) + Vector3::new(s_disp, 0.0, 0.0);
    let start_rotation = turn.inverse() * guess_end.rotation;
    let start_guess = Pose::new(
        start_rotation,
        -(start_rotation * (origin(&guess_end) - displacement)),
    );
    let motion = CtPriors {
        start: StartPrior {
            t_target_sensor: start_guess,
            information: nalgebra::Matrix6::zeros(),
        },
        rate: Some(RatePrior {
            turn,
            information: nalgebra::Matrix3::identity() / (s_turn * s_turn),
        }),
        displacement: Some(DisplacementPrior {
            displacement_m: displacement,
            information: nalgebra::Matrix3::identity() / (s_disp * s_disp),
        }),
    };
    let ct_motion_run = |voxel: &mut VoxelFilter| {
        let cloud = filtered(voxel, &f.raw_blurred);
        register_ct_ndt_with_priors(&map, &cloud, &f.scan, &motion, &guess_end, &grid)
            .expect("ct motion prior")
            .end
    };
    let icp_run = |voxel: &mut VoxelFilter, p: &IcpParams| {
        let cloud = filtered(voxel, &f.raw);
        register_icp(&icp_model, &cloud, &initial, p).expect("icp")
    };
    report("ndt/grid", &ndt_run(&mut voxel, &grid), &f.truth);
    report("ndt/kdtree", &ndt_run(&mut voxel, &tree), &f.truth);
    let ndt_static = register_ndt(&map, &blurred, &guess_end, &grid).expect("ndt");
    report("ndt on the blurred frame", &ndt_static, &f.truth);
    report("ct_ndt/grid (end pose)", &ct_run(&mut voxel), &f.truth);
    report(
        "ct_ndt free start (end pose)",
        &ct_free_run(&mut voxel),
        &f.truth,
    );
    report(
        "ct_ndt motion prior (end pose)",
        &ct_motion_run(&mut voxel),
        &f.truth,
    );
    let from_truth = register_ct_ndt(&map, &blurred, &f.scan, &f.truth_start, &f.truth, &grid);
    report(
        "ct_ndt/grid from the true end pose",
        &from_truth.expect("ct"),
        &f.truth,
    );
    let r = icp_run(&mut voxel, &icp);
    report("icp/grid", &r, &f.truth);
    eprintln!(
        "icp f_CONV {:.2} mm²",
        r.f_conv_m2.unwrap_or(f64::NAN) * 1e6
    );
    report("icp/kdtree", &icp_run(&mut voxel, &icp_tree), &f.truth);

    // A wide acquisition stage (2 m correspondences, 10 iterations, from
    // 20° / 50 cm off) with exact kd-tree searches and through the far
    // lookup of template matching (20 cm voxels within 6 m of the model).
    let far_model = IcpModel::new(&f.model).expect("icp model");
    let t0 = Instant::now();
    let far_model = far_model.with_far_lookup(6.0, 0.2).expect("far lookup");
    eprintln!(
        "far lookup built in {:.0} ms: {:?}",
        t0.elapsed().as_secs_f64() * 1e3,
        far_model.far_lookup_stats()
    );
    let wide_start = offset(&f.truth, 20.0, 0.5);
    let wide = IcpParams {
        max_distance_m: 2.0,
        max_iterations: 10,
        termination_increment: 1e-4,
        ..icp
    };
    let wide_far = IcpParams {
        far_lookup_from_m: Some(0.2),
        ..wide
    };
    let wide_run = |m: &IcpModel, p: &IcpParams| {
        register_icp(m, &frame, &wide_start, p).expect("wide icp stage")
    };
    report(
        "icp wide stage/exact",
        &wide_run(&icp_model, &wide),
        &f.truth,
    );
    report(
        "icp wide stage/far",
        &wide_run(&far_model, &wide_far),
        &f.truth,
    );

    {
        let cell = std::cell::RefCell::new(VoxelFilter::new(VOXEL_M).expect("voxel"));
        let v = || cell.borrow_mut();
        same_run_ratios(
            11,
            &mut [
                (
                    "ndt voxel+grid",
                    Box::new(|| {
                        black_box(ndt_run(&mut v(), &grid));
                    }),
                ),
                (
                    "ndt voxel+kdtree",
                    Box::new(|| {
                        black_box(ndt_run(&mut v(), &tree));
                    }),
                ),
                (
                    "voxel filter",
                    Box::new(|| {
                        black_box(filtered(&mut v(), &f.raw));
                    }),
                ),
                (
                    "ct_ndt voxel+grid",
                    Box::new(|| {
                        black_box(ct_run(&mut v()));
                    }),
                ),
                (
                    "ct_ndt free start",
                    Box::new(|| {
                        black_box(ct_free_run(&mut v()));
                    }),
                ),
                (
                    "ct_ndt motion prior",
                    Box::new(|| {
                        black_box(ct_motion_run(&mut v()));
                    }),
                ),
                (
                    "icp voxel+grid",
                    Box::new(|| {
                        black_box(icp_run(&mut v(), &icp));
                    }),
                ),
                (
                    "icp voxel+kdtree",
                    Box::new(|| {
                        black_box(icp_run(&mut v(), &icp_tree));
                    }),
                ),
                (
                    "icp wide stage exact",
                    Box::new(|| {
                        black_box(wide_run(&icp_model, &wide));
                    }),
                ),
                (
                    "icp wide stage far",
                    Box::new(|| {
                        black_box(wide_run(&far_model, &wide_far));
                    }),
                ),
            ],
        );
    }

    let mut g = c.benchmark_group("map");
    g.sample_size(10);
    g.bench_function("build", |b| {
        b.iter(|| NdtMap::build(black_box(&f.model), &map_params))
    });
    g.bench_function("load_from_bytes", |b| {
        b.iter(|| NdtMap::from_bytes(black_box(&bytes)))
    });
    g.finish();

    let mut g = c.benchmark_group("ndt");
    g.bench_function("voxel_grid_2deg_3cm", |b| {
        b.iter(|| ndt_run(&mut voxel, black_box(&grid)))
    });
    g.bench_function("voxel_kdtree_2deg_3cm", |b| {
        b.iter(|| ndt_run(&mut voxel, black_box(&tree)))
    });
    g.bench_function("voxel_filter_only", |b| {
        b.iter(|| filtered(&mut voxel, black_box(&f.raw)))
    });
    g.finish();

    let mut g = c.benchmark_group("ct_ndt");
    g.bench_function("voxel_grid_10dps_blur", |b| {
        b.iter(|| ct_run(black_box(&mut voxel)))
    });
    g.bench_function("free_start_voxel_grid_10dps_blur", |b| {
        b.iter(|| ct_free_run(black_box(&mut voxel)))
    });
    g.bench_function("motion_prior_voxel_grid_10dps_blur", |b| {
        b.iter(|| ct_motion_run(black_box(&mut voxel)))
    });
    g.finish();

    let mut g = c.benchmark_group("icp");
    g.sample_size(10);
    g.bench_function("voxel_grid_2deg_3cm", |b| {
        b.iter(|| icp_run(&mut voxel, black_box(&icp)))
    });
    g.bench_function("voxel_kdtree_2deg_3cm", |b| {
        b.iter(|| icp_run(&mut voxel, black_box(&icp_tree)))
    });
    g.bench_function("model_build", |b| {
        b.iter(|| IcpModel::new(black_box(&f.model)))
    });
    g.bench_function("wide_stage_2m_exact", |b| {
        b.iter(|| wide_run(&icp_model, black_box(&wide)))
    });
    g.bench_function("wide_stage_2m_far", |b| {
        b.iter(|| wide_run(&far_model, black_box(&wide_far)))
    });
    g.finish();
}

criterion_group!(registration, benches);
criterion_main!(registration);
