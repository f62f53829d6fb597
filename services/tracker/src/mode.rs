//! The four tracking modes compared in seed 000 §4.2.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// How each frame is registered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrackingMode {
    /// Smoothed NDT with the previous pose as the guess (seed 000 Fig. 2).
    Ndt,
    /// Smoothed NDT on a motion-compensated cloud (Eq. 12), seeded by the
    /// filter prediction (Fig. 3).
    Deblur,
    /// Continuous-time NDT (Eq. 13-15) seeded by the filter (Fig. 4).
    CtNdt,
    /// Point-to-point ICP with the previous pose as the guess (Fig. 2).
    Icp,
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
    }
}
