//! What the receiver makes of one beam's echoes (a departure from seed 004
//! §IV.A; `docs/design/echo-separation.md`).
//!
//! Seed 004 averages, weighted by intensity, the depths of every echo of a
//! beam: the direct echo and the reflected one of each ray, and the rays of
//! the divergent beam. That is what a pulsed receiver sees when the echoes
//! overlap in time: two surfaces closer than the pulse's range extent merge
//! into one return between them (the divergence artefacts of its Fig. 6b).
//! Echoes farther apart than that come back as separate pulses, and a
//! single-return sensor reports one of them, not a point between them where
//! nothing reflected. With a test facility behind the target the difference
//! is large: a surface that mirrors the floor 2-4 m away returned an average
//! 5-50 cm behind itself, on up to 85 % of the target's returns.
//!
//! Here the echoes are grouped by depth (a gap over `separation_m` starts a
//! new group), and the group with the most energy is reported: its
//! intensity-weighted depth, its energy, and whether its strongest echo met
//! the facility first. With an infinite separation there is one group: seed
//! 004's average.

/// Echoes one beam can return: a direct and a reflected echo per ray.
pub(crate) const MAX_ECHOES: usize = 2 * MAX_RAYS_PER_BEAM;

/// Divergent rays a beam may have (`SensorConfig::divergent_rays`).
pub const MAX_RAYS_PER_BEAM: usize = 16;

/// One echo: its depth along the beam, its energy (the ray's divergence
/// weight times its return factor) and whether its ray met the facility
/// first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Echo {
    /// Path length / 2 seen along the beam axis (m).
    pub depth: f64,
    /// Divergence weight × return factor (m⁻²).
    pub energy: f64,
    /// The ray's first surface is facility clutter.
    pub clutter: bool,
}

/// The return the receiver reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Detected {
    /// Intensity-weighted depth of the reported group (m).
    pub depth: f64,
    /// Energy of the reported group (m⁻²).
    pub energy: f64,
    /// The group's strongest echo met the facility first.
    pub clutter: bool,
}

/// The echoes of one beam, on the stack.
#[derive(Debug, Clone)]
pub(crate) struct BeamEchoes {
    echoes: [Echo; MAX_ECHOES],
    len: usize,
}

impl Default for BeamEchoes {
    fn default() -> Self {
        let none = Echo {
            depth: 0.0,
            energy: 0.0,
            clutter: false,
        };
        Self {
            echoes: [none; MAX_ECHOES],
            len: 0,
        }
    }
}

impl BeamEchoes {
    /// Adds an echo with positive energy (others carry nothing); beyond
    /// [`MAX_ECHOES`] echoes are dropped (the configuration bounds the rays).
    pub(crate) fn push(&mut self, echo: Echo) {
        if echo.energy > 0.0 && self.len < MAX_ECHOES {
            self.echoes[self.len] = echo;
            self.len += 1;
        }
    }

    /// The reported return: the most energetic group of echoes no more than
    /// `separation_m` apart in depth (single linkage), or `None` without
    /// an echo.
    pub(crate) fn detect(&mut self, separation_m: f64) -> Option<Detected> {
        let echoes = &mut self.echoes[..self.len];
        if echoes.is_empty() {
            return None;
        }
        if separation_m.is_infinite() {
            // One group, summed in the order the rays were traced.
            return Some(summarise(echoes));
        }
        echoes.sort_unstable_by(|a, b| a.depth.total_cmp(&b.depth));
        let mut best: Option<Detected> = None;
        let mut start = 0;
        for end in 1..=echoes.len() {
            let split =
                end == echoes.len() || echoes[end].depth - echoes[end - 1].depth > separation_m;
            if split {
                let group = summarise(&echoes[start..end]);
                if best.is_none_or(|b| group.energy > b.energy) {
                    best = Some(group);
                }
                start = end;
            }
        }
        best
    }
}

/// One group's intensity-weighted depth, energy and strongest echo's label.
fn summarise(group: &[Echo]) -> Detected {
    let energy: f64 = group.iter().map(|e| e.energy).sum();
    let depth = group.iter().map(|e| e.energy * e.depth).sum::<f64>() / energy;
    // The first of the strongest, in the order the echoes came.
    let mut strongest = (0.0, false);
    for e in group {
        if e.energy > strongest.0 {
            strongest = (e.energy, e.clutter);
        }
    }
    Detected {
        depth,
        energy,
        clutter: strongest.1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn echo(depth: f64, energy: f64) -> Echo {
        Echo {
            depth,
            energy,
            clutter: false,
        }
    }

    fn beam(echoes: &[Echo]) -> BeamEchoes {
        let mut b = BeamEchoes::default();
        echoes.iter().for_each(|e| b.push(*e));
        b
    }

    #[test]
    fn an_infinite_separation_is_seed_004s_weighted_average() {
        let d = beam(&[echo(10.0, 3.0), echo(13.0, 1.0)])
            .detect(f64::INFINITY)
            .unwrap();
        assert!((d.depth - 10.75).abs() < 1e-12);
        assert!((d.energy - 4.0).abs() < 1e-12);
    }

    #[test]
    fn separate_echoes_report_the_strongest_group_whole() {
        // A weak direct echo and a stronger mirror echo 2.5 m behind: the
        // receiver reports the mirror echo, not a point between them.
        let d = beam(&[echo(10.0, 1.0), echo(12.5, 2.0)])
            .detect(0.75)
            .unwrap();
        assert_eq!((d.depth, d.energy), (12.5, 2.0));
        // Echoes within the pulse's extent merge; the group of two at 10 m
        // (energy 1.6) outweighs the single one at 12 m (1.5).
        let d = beam(&[echo(12.0, 1.5), echo(10.0, 1.0), echo(10.4, 0.6)])
            .detect(0.75)
            .unwrap();
        assert!((d.depth - 10.15).abs() < 1e-12, "{d:?}");
        assert!((d.energy - 1.6).abs() < 1e-12);
    }

    #[test]
    fn the_label_is_the_strongest_echo_of_the_reported_group() {
        let mut b = beam(&[echo(10.0, 1.0)]);
        b.push(Echo {
            depth: 10.2,
            energy: 2.0,
            clutter: true,
        });
        assert!(b.detect(0.75).unwrap().clutter);
    }

    #[test]
    fn no_energy_no_echo() {
        assert_eq!(beam(&[]).detect(0.75), None);
        assert_eq!(beam(&[echo(10.0, 0.0)]).detect(0.75), None);
        let mut full = BeamEchoes::default();
        (0..MAX_ECHOES + 3).for_each(|k| full.push(echo(k as f64, 1.0)));
        assert_eq!(full.len, MAX_ECHOES);
    }
}
