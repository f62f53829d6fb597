//! Error-over-time plots like seed 000 Fig. 9 and Fig. 11: angular error
//! (deg) and position error (cm) against time, one line per method.
//!
//! The PNG backend renders text with the DejaVu Sans font embedded by the
//! `dejavu` crate, so plotting needs no system fonts and downloads nothing.
//! A path ending in `.svg` writes an SVG instead.

use anyhow::{Context, Result, bail};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// One method's error series.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Time of each sample (s).
    pub t: &'a [f64],
    /// Angular error (deg); NaN where the frame had no estimate.
    pub ang_err_deg: &'a [f64],
    /// Position error (cm); NaN where the frame had no estimate.
    pub pos_err_cm: &'a [f64],
    /// The method lost the target in truth (errors of 180°): it does not
    /// set the axis range when another method did not, and is drawn
    /// clipped at the top, labelled so, as seed 000 Fig. 11 leaves out the
    /// methods that failed.
    pub diverged: bool,
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is valid; a failure would only lose the text.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Draws the two-panel error plot of `series` to `path` (`.png` or `.svg`).
pub fn plot_errors(path: &Path, title: &str, series: &[Series<'_>]) -> Result<()> {
    register_font();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let size = (1100, 800);
    match ext.as_str() {
        "png" => draw(
            BitMapBackend::new(path, size).into_drawing_area(),
            title,
            series,
        ),
        "svg" => draw(
            SVGBackend::new(path, size).into_drawing_area(),
            title,
            series,
        ),
        other => bail!("unsupported plot format {other:?}: use a .png or .svg file name"),
    }
    .with_context(|| format!("writing plot {}", path.display()))
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    series: &[Series<'_>],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let root = root
        .titled(title, ("sans-serif", 24))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let panels = root.split_evenly((2, 1));
    panel(&panels[0], "angular error [deg]", series, |s| s.ang_err_deg)?;
    panel(&panels[1], "position error [cm]", series, |s| s.pos_err_cm)?;
    root.present().map_err(|e| anyhow::anyhow!("{e:?}"))?;
    Ok(())
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    y_label: &str,
    series: &[Series<'_>],
    pick: impl for<'s> Fn(&'s Series<'_>) -> &'s [f64],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let t_max = series
        .iter()
        .flat_map(|s| s.t.iter().copied())
        .fold(1.0_f64, f64::max);
    let t_min = series
        .iter()
        .flat_map(|s| s.t.iter().copied())
        .fold(t_max, f64::min);
    let y_max = y_range(series, &pick);
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(t_min..t_max.max(t_min + 1.0), 0.0..y_max)
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .y_desc(y_label)
        .label_style(("sans-serif", 16))
        .draw()
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    for (k, s) in series.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let points: Vec<(f64, f64)> =
            s.t.iter()
                .zip(pick(s))
                .filter(|(_, v)| v.is_finite())
                .map(|(t, v)| (*t, v.min(y_max)))
                .collect();
        let clipped = pick(s).iter().any(|v| *v > y_max);
        let label = if clipped {
            format!("{} (clipped)", s.label)
        } else {
            s.label.to_string()
        };
        chart
            .draw_series(LineSeries::new(points, color.stroke_width(1)))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    Ok(())
}

/// Top of the y axis: 10% above the largest finite value of the series
/// that did not diverge (of all of them when every one did).
fn y_range(series: &[Series<'_>], pick: &impl for<'s> Fn(&'s Series<'_>) -> &'s [f64]) -> f64 {
    let all_diverged = series.iter().all(|s| s.diverged);
    series
        .iter()
        .filter(|s| all_diverged || !s.diverged)
        .flat_map(|s| pick(s).iter().copied().filter(|v| v.is_finite()))
        .fold(0.0_f64, f64::max)
        .max(1e-3)
        * 1.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_png_and_svg_and_rejects_other_formats() {
        let dir = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..50).map(f64::from).collect();
        let a: Vec<f64> = t.iter().map(|x| (x * 0.2).sin().abs()).collect();
        let p: Vec<f64> = t.iter().map(|x| 2.0 + (x * 0.1).cos()).collect();
        let s = [Series {
            label: "ndt",
            t: &t,
            ang_err_deg: &a,
            pos_err_cm: &p,
            diverged: false,
        }];
        let png = dir.path().join("e.png");
        plot_errors(&png, "test", &s).unwrap();
        assert!(std::fs::metadata(&png).unwrap().len() > 1000);
        let svg = dir.path().join("e.svg");
        plot_errors(&svg, "test", &s).unwrap();
        assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
        assert!(plot_errors(&dir.path().join("e.jpg"), "t", &s).is_err());
    }

    fn angular<'s>(s: &'s Series<'_>) -> &'s [f64] {
        s.ang_err_deg
    }

    #[test]
    fn a_diverged_method_does_not_set_the_scale_unless_all_did() {
        let t = [0.0, 1.0, 2.0];
        let (good, bad) = ([0.5, 1.0, 2.0], [3.0, 90.0, 180.0]);
        let series = |a, diverged| Series {
            label: "m",
            t: &t,
            ang_err_deg: a,
            pos_err_cm: a,
            diverged,
        };
        let both = [series(&good, false), series(&bad, true)];
        assert!((y_range(&both, &angular) - 2.2).abs() < 1e-12);
        let failed = [series(&bad, true)];
        assert!((y_range(&failed, &angular) - 198.0).abs() < 1e-9);
        let dir = tempfile::tempdir().unwrap();
        plot_errors(&dir.path().join("c.png"), "clipped", &both).unwrap();
    }
}
