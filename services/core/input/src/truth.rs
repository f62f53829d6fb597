//! Scan times from the `truth.csv` written by `spacepose sim` (columns
//! documented in `tools/eval/src/truth_csv.rs`; only `frame`,
//! `scan_start_s` and `scan_end_s` are used here, found by name).

use crate::error::InputError;
use std::collections::BTreeMap;
use std::path::Path;

/// Scan interval of one frame (s, sensor clock).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanTimes {
    /// Scan start (s).
    pub scan_start_s: f64,
    /// Scan end (s).
    pub scan_end_s: f64,
}

/// Parsed `truth.csv`: scan times by frame index, plus the rows rejected.
#[derive(Debug, Default)]
pub struct TruthTimes {
    /// Scan times keyed by frame index.
    pub times: BTreeMap<u64, ScanTimes>,
    /// Malformed rows ([`InputError::TruthRow`]), skipped.
    pub rejected: Vec<InputError>,
}

impl TruthTimes {
    /// Reads `path`.
    ///
    /// # Errors
    /// [`InputError::Truth`] when the file cannot be read or its header has
    /// no `frame`, `scan_start_s` or `scan_end_s` column.
    pub fn read(path: &Path) -> Result<TruthTimes, InputError> {
        let text = std::fs::read_to_string(path).map_err(|e| InputError::Truth {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        Self::parse(path, &text)
    }

    /// Parses the text of a truth file (`path` names it in errors).
    pub fn parse(path: &Path, text: &str) -> Result<TruthTimes, InputError> {
        let mut lines = text.lines();
        let header: Vec<&str> = lines
            .next()
            .unwrap_or("")
            .split(',')
            .map(str::trim)
            .collect();
        let column = |name: &str| {
            header
                .iter()
                .position(|c| *c == name)
                .ok_or_else(|| InputError::Truth {
                    path: path.to_owned(),
                    message: format!("no `{name}` column in the header"),
                })
        };
        let (i_frame, i_start, i_end) = (
            column("frame")?,
            column("scan_start_s")?,
            column("scan_end_s")?,
        );
        let mut out = TruthTimes::default();
        for (n, line) in lines.enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let bad = |message: String| InputError::TruthRow {
                path: path.to_owned(),
                line: n + 2,
                message,
            };
            let f: Vec<&str> = line.split(',').map(str::trim).collect();
            let field = |i: usize| f.get(i).copied().unwrap_or("");
            let frame = field(i_frame).parse::<u64>();
            let start = field(i_start).parse::<f64>();
            let end = field(i_end).parse::<f64>();
            match (frame, start, end) {
                (Ok(frame), Ok(s), Ok(e)) if s.is_finite() && e.is_finite() && s <= e => {
                    out.times.insert(
                        frame,
                        ScanTimes {
                            scan_start_s: s,
                            scan_end_s: e,
                        },
                    );
                }
                (Ok(_), Ok(s), Ok(e)) => out.rejected.push(bad(format!(
                    "scan interval [{s}, {e}] is not finite and ordered"
                ))),
                _ => out.rejected.push(bad(format!("cannot parse `{line}`"))),
            }
        }
        Ok(out)
    }

    /// Median interval between consecutive scan ends (s), if at least two
    /// frames and a positive median.
    pub fn median_period_s(&self) -> Option<f64> {
        let ends: Vec<f64> = self.times.values().map(|t| t.scan_end_s).collect();
        let mut d: Vec<f64> = ends.windows(2).map(|w| w[1] - w[0]).collect();
        if d.is_empty() {
            return None;
        }
        d.sort_by(f64::total_cmp);
        let m = d[d.len() / 2];
        (m.is_finite() && m > 0.0).then_some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "frame,scan_start_s,scan_end_s,points,px_m";

    #[test]
    fn rows_parse_and_bad_rows_are_reported() {
        let text = format!(
            "{HEADER}\n0,0.28,1.0,10,5\n1,1.28,2.0,10,5\n2,x,3.0,1,1\n3,4.0,3.5,1,1\n\n4,4.28,5.0\n5,5.28,6.0,10,5\n"
        );
        let t = TruthTimes::parse(Path::new("truth.csv"), &text).unwrap();
        assert_eq!(t.times.len(), 4);
        assert_eq!(t.times[&4].scan_end_s, 5.0);
        assert_eq!(t.rejected.len(), 2);
        assert!(matches!(
            t.rejected[0],
            InputError::TruthRow { line: 4, .. }
        ));
        assert_eq!(t.median_period_s(), Some(1.0));
    }

    #[test]
    fn a_header_without_the_needed_columns_is_an_error() {
        let e = TruthTimes::parse(Path::new("truth.csv"), "frame,scan_end_s\n0,1\n");
        assert!(matches!(e, Err(InputError::Truth { .. })));
        assert!(matches!(
            TruthTimes::parse(Path::new("truth.csv"), ""),
            Err(InputError::Truth { .. })
        ));
    }
}
