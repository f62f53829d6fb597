use super::*;

fn frame(frame: usize, status: TrackStatus, ang: f64, pos_cm: f64) -> FrameRecord {
    FrameRecord {
        frame,
        t: frame as f64,
        range_m: 15.0,
        status,
        q_sensor_target: [1.0, 0.0, 0.0, 0.0],
        p_sensor_target_m: [0.0; 3],
        ang_err_deg: ang,
        pos_err_cm: pos_cm,
        err_rotvec_target_deg: [0.0; 3],
        w_err_deg_s: 0.0,
        w_err_along_deg_s: 0.0,
        time_ms: 1.0,
        iterations: 5,
        cost_mean: 1.0,
        inlier_fraction: 0.9,
        degenerate_directions: 0,
        weakest_lever_arm_m: 0.1,
        held_sigma_deg: f64::NAN,
        held_translations: 0,
        weakest_translation_cosine: 0.2,
        held_sigma_cm: f64::NAN,
        points_in: 1000,
        points_used: 900,
        points_behind: 0,
        crop: None,
        refit: false,
        innovation_rot_deg: f64::NAN,
        nis: f64::NAN,
        reason: String::new(),
        blur_lag_deg: 0.0,
        fallback: false,
        start_up: false,
        nees: f64::NAN,
        filter_ang_err_deg: f64::NAN,
        filter_pos_err_cm: f64::NAN,
        filter_nees: f64::NAN,
        acquisition: None,
    }
}

#[test]
fn a_run_counts_its_start_up_and_its_failures() {
    use TrackStatus::*;
    let series = vec![
        frame(0, Tracking, 6.0, 2.0), // start-up: in the whole-run max
        frame(1, Tracking, 1.0, 2.0),
        frame(2, Tracking, 12.0, 3.0), // silent
        frame(3, Degraded, 11.0, 4.0), // diverged, not silent
        frame(4, Tracking, 1.0, 60.0), // silent by position
        frame(5, Lost, f64::NAN, f64::NAN),
    ];
    let f = figures(9, &series, 1);
    assert_eq!(f.seed, 9);
    assert_eq!(f.ang_max_deg, 12.0);
    assert_eq!(f.ang_max_after_warmup_deg, 12.0);
    assert!((f.ang_mean_deg - 31.0 / 5.0).abs() < 1e-12);
    assert_eq!(f.pos_max_cm, 60.0);
    assert_eq!((f.lost, f.degraded, f.diverged, f.silent), (1, 1, 4, 2));
    assert!(
        f.nees_median.is_nan() && f.nees_above_95.is_nan(),
        "no covariance"
    );
    let mut with_nees = series.clone();
    for (r, nees) in with_nees.iter_mut().zip([1.0, 4.0, 20.0, 30.0, 5.0]) {
        r.nees = nees;
        r.filter_nees = nees * 10.0;
        r.nis = nees * 2.0;
    }
    let f = figures(9, &with_nees, 1);
    assert_eq!((f.nees_median, f.nees_above_95), (5.0, 0.4));
    assert_eq!((f.filter_nees_median, f.filter_nees_above_95), (50.0, 0.8));
    assert_eq!((f.nis_median, f.nis_above_95), (10.0, 0.4));
    let warm = figures(9, &series[..2], 1);
    assert_eq!(
        (warm.ang_max_deg, warm.ang_max_after_warmup_deg),
        (6.0, 1.0)
    );
}

#[test]
fn spread_gives_mean_p95_max_and_a_t_interval() {
    let v: Vec<f64> = (1..=20).map(f64::from).collect();
    let s = spread(&v);
    assert_eq!((s.mean, s.p95, s.max), (10.5, 19.0, 20.0));
    // sd of 1..20 = 5.916; t(19) = 2.093.
    let half = 2.093 * 5.916_079_783 / 20f64.sqrt();
    assert!((s.ci95[1] - s.mean - half).abs() < 1e-6, "{:?}", s.ci95);
    assert!((s.mean - s.ci95[0] - half).abs() < 1e-6);
    let one = spread(&[3.0]);
    assert_eq!((one.mean, one.p95, one.max), (3.0, 3.0, 3.0));
    assert!(one.ci95[1].is_infinite());
    assert!(spread(&[1.0, f64::NAN]).mean.is_nan());
    assert!(spread(&[]).max.is_nan());
}

#[test]
fn a_run_that_waits_on_a_thread_using_rayon_does_not_deadlock() {
    // The shape of a run from init's acquisitions: the run sleeps until
    // another thread's parallel work (template matching) is done.
    let evaluate = |seed: u64| -> Result<TrackingReport> {
        let worker = std::thread::spawn(|| (0..10_000u64).into_par_iter().sum::<u64>());
        while !worker.is_finished() {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        let sum = worker
            .join()
            .map_err(|_| anyhow::anyhow!("worker panicked"))?;
        Err(anyhow::anyhow!("seed {seed}: {sum}"))
    };
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let seeds: Vec<u64> = (1..=8).collect();
        let _ = tx.send(monte_carlo(evaluate, "test", &seeds, "").map(|_| ()));
    });
    let result = rx
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("the Monte-Carlo deadlocked");
    let error = result.expect_err("every run failed").to_string();
    assert!(error.contains("49995000"), "{error}");
}
