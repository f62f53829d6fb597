//! `spacepose track`: the suite's frame pipeline in one process on a
//! recording (a PCD/PLY directory, an MCAP file or a ROS 2 bag), from an
//! acquisition or a given pose, writing one pose per frame.
//!
//! The pipeline is [`DeployedSuite`]: the deployed ingest, tracker, filter
//! and init nodes on one in-memory bus, with init's acquisitions in
//! lockstep, so the same recording gives bit-identical poses. A recording
//! with truth (`truth.csv` of `spacepose sim`) is scored against it at the
//! end; the truth never reaches the pipeline.

mod args;
mod config;
mod pose_csv;
mod record;
mod summary;
mod truth;

pub use args::{InitChoice, TrackArgs};
pub use config::TrackConfig;
pub use pose_csv::PoseRow;
pub use summary::{Errors, TrackSummary};

use crate::common::progress_bar;
use crate::tracking::DeployedSuite;
use anyhow::{Context, Result, bail};
use record::McapOut;
use spacepose_input::InputFrame;
use spacepose_messages::{AcquisitionMethod, AcquisitionResult, CloudHeader, Name};
use summary::Scorer;
use tracing::{info, warn};

/// Runs the command.
pub fn run(args: &TrackArgs) -> Result<()> {
    let mut config = TrackConfig::load(args.config.as_deref())?;
    let package = spacepose_prepare::resolve(&args.target, args.scale)
        .with_context(|| format!("--target {}", args.target))?;
    let spec = match &package.dir {
        Some(dir) => std::path::absolute(dir)?.to_string_lossy().into_owned(),
        None => args.target.clone(),
    };
    config.set_target(
        &spec,
        if package.dir.is_some() {
            1.0
        } else {
            args.scale
        },
    );
    if let Some(topic) = &args.topic {
        config.input.topic = Some(topic.clone());
    }
    if let Some(mode) = args.mode {
        config.tracker.tracker.mode = mode;
    }
    config.validate()?;
    let mut mcap = match args.out.as_deref() {
        Some(out) if has_extension(out, "mcap") => Some(McapOut::create(out, &package.target)?),
        Some(out) if !has_extension(out, "csv") => {
            bail!(
                "--out {}: the poses go to a .csv or .mcap file",
                out.display()
            )
        }
        _ => None,
    };
    let (summary, rows) = track(args, &config, package.target.symmetries(), mcap.as_mut())?;
    match (args.out.as_deref(), mcap) {
        (Some(out), Some(m)) => println!("{} written to {}", m.close()?, out.display()),
        (Some(out), None) => {
            pose_csv::write(out, &rows)?;
            println!("poses written to {}", out.display());
        }
        _ => {}
    }
    print!("{}", summary.render());
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&summary)?;
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// Tracks the recording of `args` with `config`: the summary and the rows.
pub fn track(
    args: &TrackArgs,
    config: &TrackConfig,
    symmetries: &[nalgebra::Rotation3<f64>],
    mut mcap: Option<&mut McapOut>,
) -> Result<(TrackSummary, Vec<PoseRow>)> {
    let mut recording = spacepose_input::open(&args.input, &config.input)
        .with_context(|| format!("--input {}", args.input.display()))?;
    info!("reading {}", recording.describe());
    for w in recording.warnings() {
        warn!("{w}");
    }
    let mut derived_warned = false;
    let truth = truth::read_dir_truth(&args.input)?;
    let suite_configs = config.suite();
    let (model, _) = suite_configs
        .tracker
        .build_model()
        .context("building the NDT map")?;
    let mut suite = match &args.init {
        InitChoice::Acquire => {
            DeployedSuite::with_init(&suite_configs, model, config.init.clone())?
        }
        InitChoice::Given(_) => DeployedSuite::new(&suite_configs, model)?,
    };
    let limit = args.frames.unwrap_or(usize::MAX);
    let bar = progress_bar(
        recording.len_hint().unwrap_or(0).min(limit) as u64,
        "tracking",
    );
    let mut scorer = Scorer::new(truth.as_ref(), symmetries);
    let mut rows = Vec::new();
    let mut sequence = 0u64;
    for item in recording.frames() {
        if rows.len() >= limit {
            break;
        }
        let frame = match item {
            Ok(f) => f,
            Err(e) => {
                warn!("frame skipped: {e}");
                scorer.summary_mut().frames_skipped += 1;
                continue;
            }
        };
        if frame.times_derived() && !derived_warned {
            warn!(
                "{}: no per-point time field; times derived from the scan interval and the \
                 point order (counted in the summary)",
                frame.origin
            );
            derived_warned = true;
        }
        if let (0, InitChoice::Given(pose)) = (sequence, &args.init) {
            suite.acquire(given_acquisition(pose, &frame)?);
        }
        let row = track_frame(
            &mut suite,
            &mut scorer,
            &frame,
            sequence,
            mcap.as_deref_mut(),
        )?;
        rows.push(row);
        sequence += 1;
        bar.inc(1);
    }
    bar.finish_and_clear();
    if rows.is_empty() {
        bail!("no frame of {} could be read", args.input.display());
    }
    Ok((scorer.finish(), rows))
}

/// One frame through the suite.
fn track_frame(
    suite: &mut DeployedSuite,
    scorer: &mut Scorer<'_>,
    frame: &InputFrame,
    sequence: u64,
    mcap: Option<&mut McapOut>,
) -> Result<PoseRow> {
    if frame.times_derived() {
        scorer.summary_mut().frames_derived_times += 1;
    }
    let header = CloudHeader::new(sequence, frame.scan_start_s, frame.scan_end_s);
    let answer = suite.track(header, frame.points.clone())?;
    if let Some(m) = mcap {
        m.frame(&header, &frame.points, &answer.sent)?;
    }
    let status = pose_csv::status_name(&answer.estimate);
    scorer.frame(frame.index, &answer.estimate, status);
    let mut acquired = "";
    for a in &answer.acquisitions {
        scorer.acquisition(frame.index, a);
        if a.success == 1 {
            acquired = AcquisitionMethod::from_u8(a.method).map_or("", AcquisitionMethod::as_str);
        }
    }
    Ok(PoseRow {
        frame: frame.index,
        scan_start_s: frame.scan_start_s,
        scan_end_s: frame.scan_end_s,
        estimate: answer.estimate,
        acquired,
    })
}

fn has_extension(path: &std::path::Path, ext: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// The operator's pose as an accepted acquisition of the first frame.
fn given_acquisition(
    pose: &spacepose_geometry::Pose,
    first: &InputFrame,
) -> Result<AcquisitionResult> {
    let mut a = AcquisitionResult::new();
    a.method = AcquisitionMethod::Given as u8;
    a.success = 1;
    a.sequence = 0;
    a.t_s = first.scan_end_s;
    a.set_pose(pose);
    a.instance = Name::new("operator")?;
    Ok(a)
}
