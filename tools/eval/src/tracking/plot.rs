//! The error-over-time plot of a tracking evaluation (seed 000 Fig. 9/11):
//! one line per mode, drawn by [`plot_errors`].

use super::report::{ModeReport, TrackingReport};
use crate::plot::{Series, plot_errors};
use anyhow::Result;
use std::path::Path;

/// Plots the errors of every mode of `report` to `path` (`.png` or `.svg`)
/// and says so.
pub fn write_plot(path: &Path, report: &TrackingReport) -> Result<()> {
    let columns: Vec<Columns> = report
        .modes
        .iter()
        .map(|(name, mode)| Columns::of(name, mode))
        .collect();
    let series: Vec<Series<'_>> = columns.iter().map(Columns::series).collect();
    plot_errors(path, &title(report), &series)?;
    println!("plot written to {}", path.display());
    Ok(())
}

/// The plot's title: scenario, target and seed.
fn title(report: &TrackingReport) -> String {
    format!(
        "{} ({}), seed {}",
        report.scenario, report.target, report.seed
    )
}

/// One mode's plotted columns, owned for a [`Series`] to borrow.
struct Columns {
    /// Mode name (the legend label).
    label: String,
    /// Scan end of each frame (s).
    t: Vec<f64>,
    /// Angular error of each frame (deg; NaN when lost).
    ang_err_deg: Vec<f64>,
    /// Position error of each frame (cm; NaN when lost).
    pos_err_cm: Vec<f64>,
    /// The mode diverged in truth on some frame.
    diverged: bool,
}

impl Columns {
    /// The columns of mode `name`'s per-frame records.
    fn of(name: &str, mode: &ModeReport) -> Self {
        Self {
            label: name.to_string(),
            t: mode.series.iter().map(|r| r.t).collect(),
            ang_err_deg: mode.series.iter().map(|r| r.ang_err_deg).collect(),
            pos_err_cm: mode.series.iter().map(|r| r.pos_err_cm).collect(),
            diverged: mode.diverged_frames > 0,
        }
    }

    /// The series to plot, borrowing these columns.
    fn series(&self) -> Series<'_> {
        Series {
            label: &self.label,
            t: &self.t,
            ang_err_deg: &self.ang_err_deg,
            pos_err_cm: &self.pos_err_cm,
            diverged: self.diverged,
        }
    }
}
