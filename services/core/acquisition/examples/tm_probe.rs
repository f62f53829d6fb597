//! Tuning probe (not the evaluation: see `spacepose eval tm`): random
//! attitudes at one range, seed 002 raster sensor with every effect.
//! Usage: tm_probe RANGE COUNT SEED [key=value ...]

use spacepose_acquisition::{CoarseToFine, TemplateMatcher, TemplateMatchingConfig, Threads};
use spacepose_geometry::so3;
use spacepose_lidar_sim::{LidarSimulator, SensorConfig};
use spacepose_model::Target;
use spacepose_scenario::{ScenarioConfig, ScenarioKind, build};
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let range: f64 = args.get(1).map_or(Ok(20.0), |s| s.parse())?;
    let count: usize = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let seed: u64 = args.get(3).map_or(Ok(1), |s| s.parse())?;
    let mut c = TemplateMatchingConfig {
        threads: Threads::Single,
        ..Default::default()
    };
    let mut kind = ScenarioKind::Random;
    let mut effects = spacepose_lidar_sim::Effects::default();
    let mut verbose = false;
    let mut only: Option<usize> = None;
    let mut oracle = false;
    // oracle=centroid: the nearest grid attitude, positioned as the matcher
    // positions a template (centroid alignment, re-centred), then screened
    // and refined like a screened candidate.
    let mut oracle_centroid = false;
    // oracle=vote: then moved to the mode of the translation votes.
    let mut oracle_vote = false;
    for kv in &args[4.min(args.len())..] {
        let (k, v) = kv.split_once('=').ok_or("key=value")?;
        match k {
            "fast" => c.fast = v.parse()?,
            "trim" => c.trimmed_centroid = v.parse()?,
            "cands" => c.icp_candidates = v.parse()?,
            "screen" => c.screen_candidates = v.parse()?,
            "screen_iters" => c.screen_iterations = v.parse()?,
            "budget" => c.screen_point_budget = v.parse()?,
            "screen_pts" => c.screen_max_points = v.parse()?,
            "rerank" => c.screen_rerank = v.parse()?,
            "recentre" => c.recentre_iterations = v.parse()?,
            "stride" => c.template_stride = v.parse()?,
            "coarse" => {
                let (s, n) = v.split_once(':').ok_or("coarse=stride:keep")?;
                c.coarse_to_fine = Some(CoarseToFine {
                    stride: s.parse()?,
                    keep: n.parse()?,
                });
            }
            "sym" => c.symmetric_correlation = v.parse()?,
            "sep" => c.candidate_separation_deg = v.parse()?,
            "corr" => c.max_correlation_points = v.parse()?,
            "stages" => {
                c.icp_stages_m = v.split(',').map(|x| x.parse()).collect::<Result<_, _>>()?
            }
            "iters" => c.icp_stage_iterations = v.parse()?,
            "threads" => {
                c.threads = if v == "1" {
                    Threads::Single
                } else {
                    Threads::All
                }
            }
            "ellipse" => kind = ScenarioKind::Ellipse,
            "ideal" => effects = spacepose_lidar_sim::Effects::none(),
            "noblur" => {
                effects.reflections = false;
                effects.beam_divergence = false;
            }
            "verbose" => verbose = true,
            "only" => only = Some(v.parse()?),
            "oracle" => {
                oracle = true;
                oracle_centroid = v == "centroid" || v == "vote";
                oracle_vote = v == "vote";
            }
            _ => return Err(format!("unknown key {k}").into()),
        }
    }
    let target = Arc::new(Target::builtin("envisat")?);
    let sensor = SensorConfig::raster_seed002();
    let m = TemplateMatcher::new(target.clone(), sensor.clone(), c)?;
    let mut sim_sensor = sensor.clone();
    sim_sensor.effects = effects;
    let sim = LidarSimulator::new(target, sim_sensor)?;
    let mut sc = ScenarioConfig::default_for(kind);
    sc.seed = seed;
    sc.range_m = range;
    sc.random_frames = count;
    let scenario = build(&sc)?;
    let (mut ok, mut t_sum, mut t_max, mut coarse_ok) = (0, 0.0, 0.0f64, 0);
    let (mut fs_max, mut ff_min) = (0.0f64, f64::INFINITY);
    let mut pts = 0;
    let mut m_sum = 0.0;
    for (i, t) in scenario.frame_end_times(count).into_iter().enumerate() {
        if only.is_some_and(|n| n != i) {
            continue;
        }
        let frame = sim.simulate(
            &scenario.state_at(t),
            &mut LidarSimulator::frame_rng(seed, i as u64),
        );
        pts += frame.points.len();
        let truth = frame.truth.t_sensor_target.rotation;
        if oracle {
            let (_, g) = m
                .grid()
                .iter()
                .min_by(|a, b| so3::distance(&a.1, &truth).total_cmp(&so3::distance(&b.1, &truth)))
                .ok_or("grid")?;
            let mut t = frame.truth.t_sensor_target.translation;
            let mut stages = m.config().icp_stages_m.clone();
            let mut start = spacepose_geometry::Pose::new(*g, t);
            if oracle_centroid {
                let pos: Vec<_> = frame.points.iter().map(|p| p.position()).collect();
                let centre = pos.iter().sum::<nalgebra::Vector3<f64>>() / pos.len() as f64;
                let renderer =
                    spacepose_acquisition::TemplateRenderer::new(m.target().clone(), m.sensor(), 1);
                t = centre;
                for _ in 0..=m.config().recentre_iterations {
                    let tpl = renderer.render(g, &t);
                    if tpl.len() < 3 {
                        break;
                    }
                    t += centre - tpl.iter().sum::<nalgebra::Vector3<f64>>() / tpl.len() as f64;
                }
                if oracle_vote {
                    let tpl = renderer.render(g, &t);
                    let bin = m.config().translation_vote_bin_m.max(0.5);
                    let mut scratch = spacepose_acquisition::VoteScratch::default();
                    t += spacepose_acquisition::vote_translation(
                        &pos,
                        &tpl,
                        (bin, 15.0),
                        150,
                        &mut scratch,
                    )
                    .unwrap_or_default();
                }
                let stride = frame
                    .points
                    .len()
                    .div_ceil(m.config().screen_max_points.max(1))
                    .max(1);
                let sub: Vec<_> = frame.points.iter().step_by(stride).copied().collect();
                let (p, score) = spacepose_acquisition::screen(
                    m.stage_model(),
                    &sub,
                    &spacepose_geometry::Pose::new(*g, t),
                    m.config(),
                )?;
                println!(
                    "oracle frame {i}: start pos err {:.2} m, screened err {:.1} deg {:.2} m score {score:.2e}",
                    (t - frame.truth.t_sensor_target.translation).norm(),
                    so3::distance(&p.rotation, &truth).to_degrees(),
                    (p.translation - frame.truth.t_sensor_target.translation).norm()
                );
                start = p;
                stages = stages.split_off(stages.len().saturating_sub(1));
            }
            let r = spacepose_acquisition::refine_with_stages(
                m.icp_model(),
                m.stage_model(),
                &frame.points,
                &start,
                m.config(),
                &stages,
            );
            let e = r
                .as_ref()
                .map(|r| so3::distance(&truth, &r.t_sensor_target.rotation).to_degrees())
                .unwrap_or(f64::NAN);
            println!(
                "oracle frame {i}: grid err {:.1} -> {:.1} deg",
                so3::distance(g, &truth).to_degrees(),
                e
            );
            continue;
        }
        match m.acquire(&frame.points) {
            Ok(o) => {
                let e = so3::distance(&truth, &o.t_sensor_target.rotation).to_degrees();
                let ec = so3::distance(&truth, &o.t_sensor_target_coarse.rotation).to_degrees();
                if verbose {
                    let d = o.t_sensor_target.translation - frame.truth.t_sensor_target.translation;
                    let body = frame.truth.t_sensor_target.rotation.inverse() * d;
                    let t_inv = frame.truth.t_sensor_target.inverse();
                    let on_array = frame
                        .points
                        .iter()
                        .filter(|p| t_inv.transform(&p.position()).x < -6.5)
                        .count();
                    println!(
                        "frame {i}: final pos err {:.2} m, in body axes [{:.2}, {:.2}, {:.2}], {:.0} % of the points on the solar array",
                        d.norm(),
                        body.x,
                        body.y,
                        body.z,
                        100.0 * on_array as f64 / frame.points.len().max(1) as f64
                    );
                    println!(
                        "frame {i}: pts {} err {e:.1} coarse {ec:.1} f_conv {:.2e} rank {} centroid-truth {:.2} m, coarse pos err {:.2} m, {:.0} ms",
                        frame.points.len(),
                        o.f_conv_m2,
                        o.chosen_rank,
                        (nalgebra::Vector3::from(o.centroid_m)
                            - frame.truth.t_sensor_target.translation)
                            .norm(),
                        (o.t_sensor_target_coarse.translation
                            - frame.truth.t_sensor_target.translation)
                            .norm(),
                        o.time_ms
                    );
                    // The second chance's vote, from the final position, at
                    // the final attitude and at the true one.
                    let pos: Vec<_> = frame.points.iter().map(|p| p.position()).collect();
                    let renderer = spacepose_acquisition::TemplateRenderer::new(
                        m.target().clone(),
                        m.sensor(),
                        1,
                    );
                    let tr = frame.truth.t_sensor_target;
                    for (name, r) in [("final", o.t_sensor_target.rotation), ("true", tr.rotation)]
                    {
                        let origin = o.t_sensor_target.translation;
                        let tpl = renderer.render(&r, &origin);
                        let mut scratch = spacepose_acquisition::VoteScratch::default();
                        let moved = spacepose_acquisition::vote_translation(
                            &pos,
                            &tpl,
                            (m.config().translation_vote_bin_m, 21.2),
                            150,
                            &mut scratch,
                        );
                        let after = origin + moved.unwrap_or_default();
                        let body = tr.rotation.inverse() * (after - tr.translation);
                        println!(
                            "frame {i}: vote at the {name} attitude: template {} pts, moved {:?}, then err [{:.2}, {:.2}, {:.2}] m",
                            tpl.len(),
                            moved.map(|v| (v.norm() * 100.0).round() / 100.0),
                            body.x,
                            body.y,
                            body.z
                        );
                    }
                }
                t_sum += o.time_ms;
                m_sum += o.matching_ms;
                t_max = t_max.max(o.time_ms);
                if ec < 30.0 {
                    coarse_ok += 1;
                }
                if e < 3.0 {
                    ok += 1;
                    fs_max = fs_max.max(o.f_conv_m2);
                } else {
                    ff_min = ff_min.min(o.f_conv_m2);
                }
            }
            Err(e) => println!("frame {i}: {e}"),
        }
    }
    let n = count as f64;
    println!(
        "range {range} n {count} seed {seed}: success {:.1}% (coarse<30°: {:.0}%), time mean {:.0} ms (matching {:.0}) max {:.0} ms, f_conv success max {:.2e} failure min {:.2e}, points {:.0}",
        100.0 * ok as f64 / n,
        100.0 * coarse_ok as f64 / n,
        t_sum / n,
        m_sum / n,
        t_max,
        fs_max,
        ff_min,
        pts as f64 / n
    );
    Ok(())
}
