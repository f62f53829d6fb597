//! The four tracking modes compared in seed 000 §4.2.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// How each frame is registered: the one declaration of the mode, in
/// configs (its kebab-case name), on the command line (the same name) and
/// on the wire (its [`TrackingMode::code`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrackingMode {
    /// Smoothed NDT with the previous pose as the guess (seed 000 Fig. 2).
    Ndt = 0,
    /// Smoothed NDT on a motion-compensated cloud (Eq. 12), seeded by the
    /// filter prediction (Fig. 3).
    Deblur = 1,
    /// Continuous-time NDT (Eq. 13-15) seeded by the filter (Fig. 4).
    CtNdt = 2,
    /// Point-to-point ICP with the previous pose as the guess (Fig. 2).
    Icp = 3,
}

impl TrackingMode {
    /// Every mode, in the order of the paper's tables.
    pub const ALL: [TrackingMode; 4] = [Self::Ndt, Self::Deblur, Self::CtNdt, Self::Icp];

    /// The command-line / config name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Ndt => "ndt",
            Self::Deblur => "deblur",
            Self::CtNdt => "ct-ndt",
            Self::Icp => "icp",
        }
    }

    /// Largest [`TrackingMode::code`].
    pub const MAX_CODE: u8 = 3;

    /// The code carried in messages (`PoseEstimate::mode`, `Command::mode`).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// The mode of a code; `None` for an unknown one.
    pub fn from_code(code: u8) -> Option<TrackingMode> {
        Self::ALL.into_iter().find(|m| m.code() == code)
    }

    /// True when the filter prediction seeds the registration.
    pub fn uses_prediction(self) -> bool {
        matches!(self, Self::Deblur | Self::CtNdt)
    }
}

impl fmt::Display for TrackingMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for TrackingMode {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| {
                format!("unknown tracking mode {s:?} (expected ndt, deblur, ct-ndt or icp)")
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for m in TrackingMode::ALL {
            assert_eq!(m.as_str().parse::<TrackingMode>(), Ok(m));
        }
        assert!("gicp".parse::<TrackingMode>().is_err());
        for (i, m) in TrackingMode::ALL.into_iter().enumerate() {
            assert_eq!(usize::from(m.code()), i);
            assert_eq!(TrackingMode::from_code(m.code()), Some(m));
        }
        assert_eq!(TrackingMode::Icp.code(), TrackingMode::MAX_CODE);
        assert_eq!(TrackingMode::from_code(TrackingMode::MAX_CODE + 1), None);
    }
}
