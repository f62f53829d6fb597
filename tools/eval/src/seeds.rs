//! The committed seed protocol (`tools/eval/seeds.toml`), compiled in so
//! that every evaluation reads the same lists: development seeds (anyone
//! may look at them while choosing anything) and blind seeds (reported,
//! never tuned on). `eval tracking --report` runs its Monte-Carlo over a
//! named list.

use anyhow::{Context, Result, bail};
use serde::Deserialize;

/// The file, as committed.
pub const SEEDS_TOML: &str = include_str!("../seeds.toml");

/// The lists of `seeds.toml`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeedLists {
    /// Scenario seeds looked at while tuning.
    pub development: Vec<u64>,
    /// Scenario seeds only reported.
    pub blind: Vec<u64>,
    /// Generated-design seeds looked at while tuning (`zoo:N`).
    pub zoo_development: Vec<u64>,
    /// Generated-design seeds only reported.
    pub zoo_blind: Vec<u64>,
}

impl SeedLists {
    /// The committed lists.
    pub fn committed() -> Result<Self> {
        toml::from_str(SEEDS_TOML).context("parsing tools/eval/seeds.toml")
    }

    /// The scenario seeds of `set`: `blind`, `development`, or a
    /// comma-separated list of seeds.
    pub fn scenario_seeds(&self, set: &str) -> Result<Vec<u64>> {
        let seeds = match set {
            "blind" => self.blind.clone(),
            "development" => self.development.clone(),
            list => list
                .split(',')
                .map(|s| {
                    s.trim().parse::<u64>().with_context(|| {
                        format!("--seeds: `{s}` is not blind, development or a seed")
                    })
                })
                .collect::<Result<Vec<_>>>()?,
        };
        if seeds.is_empty() {
            bail!("--seeds `{set}` names no seed");
        }
        Ok(seeds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn the_committed_lists_parse_and_never_overlap() {
        let s = SeedLists::committed().unwrap();
        let dev: BTreeSet<u64> = s.development.iter().copied().collect();
        let blind: BTreeSet<u64> = s.blind.iter().copied().collect();
        assert!(dev.is_disjoint(&blind), "{:?}", dev.intersection(&blind));
        assert_eq!(blind.len(), s.blind.len(), "a blind seed is listed twice");
        // Issue 25: a Monte-Carlo over at least 20 blind seeds.
        assert!(s.blind.len() >= 20, "{} blind seeds", s.blind.len());
        let zoo_dev: BTreeSet<u64> = s.zoo_development.iter().copied().collect();
        let zoo_blind: BTreeSet<u64> = s.zoo_blind.iter().copied().collect();
        assert!(zoo_dev.is_disjoint(&zoo_blind));
    }

    #[test]
    fn a_set_is_a_list_name_or_seeds() {
        let s = SeedLists::committed().unwrap();
        assert_eq!(s.scenario_seeds("blind").unwrap(), s.blind);
        assert_eq!(s.scenario_seeds("3, 7").unwrap(), vec![3, 7]);
        assert!(s.scenario_seeds("seven").is_err());
        assert!(s.scenario_seeds("").is_err());
    }
}
