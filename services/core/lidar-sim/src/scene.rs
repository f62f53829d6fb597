//! One frame's scene: the target moving with constant velocity and angular
//! velocity during the scan, the optional facility background, and the
//! tracing of one beam (divergent rays, direct and reflected echoes).

use crate::echoes::{BeamEchoes, Echo};
use crate::mismatch::ScanPath;
use crate::optics::{Cone, cos_pow, divergence_weight, mirror, phong_backscatter, sample_cone};
use crate::surface::Surface;
use nalgebra::{Rotation3, Vector3};
use rand_chacha::ChaCha8Rng;
use spacepose_geometry::so3;
use spacepose_model::{Mesh, Target};

/// Motion of the target during a scan.
#[derive(Debug, Clone, Copy)]
pub(crate) enum TargetMotion<'a> {
    /// The scan-end truth extrapolated backwards with constant velocity
    /// (seed 000 Eq. 8) and angular velocity (Eq. 9): the motion the
    /// filter assumes.
    Constant(ConstantMotion),
    /// The world's own motion, sampled over the scan ([`crate::mismatch`]).
    Sampled(&'a ScanPath),
}

/// `R(t) = R_end Exp(ω (t - t_end))`, `p(t) = p_end + v (t - t_end)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ConstantMotion {
    /// Scan-end rotation body → sensor.
    pub r_sensor_target: Rotation3<f64>,
    /// Scan-end position of the centre of mass in the sensor frame.
    pub t_sensor_target: Vector3<f64>,
    /// Velocity of the centre of mass in the sensor frame (m/s).
    pub v_sensor: Vector3<f64>,
    /// Angular velocity in the body frame (rad/s).
    pub w_target: Vector3<f64>,
    /// Scan-end time (s).
    pub t_end: f64,
    /// When false the target stays at its scan-end pose for every ray.
    pub blur: bool,
}

impl TargetMotion<'_> {
    #[inline]
    fn position(&self, t: f64) -> Vector3<f64> {
        match self {
            TargetMotion::Constant(m) if m.blur => m.t_sensor_target + m.v_sensor * (t - m.t_end),
            TargetMotion::Constant(m) => m.t_sensor_target,
            TargetMotion::Sampled(path) => path.position(t),
        }
    }

    #[inline]
    fn rotation(&self, t: f64) -> Rotation3<f64> {
        match self {
            TargetMotion::Constant(m) if m.blur => {
                m.r_sensor_target * so3::exp(&(m.w_target * (t - m.t_end)))
            }
            TargetMotion::Constant(m) => m.r_sensor_target,
            TargetMotion::Sampled(path) => path.rotation(t),
        }
    }
}

/// Target pose at one ray's time.
struct Snapshot {
    r: Rotation3<f64>,
    p: Vector3<f64>,
}

/// First surface met by a ray, in the sensor frame.
struct SceneHit {
    distance: f64,
    normal: Vector3<f64>,
    surface: Surface,
    clutter: bool,
}

/// The combined echo of one beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BeamEcho {
    /// Intensity-weighted depth along the beam axis (m).
    pub depth: f64,
    /// Received return factor `Σ w ρ f_Phong / r² / Σ w` (m⁻²).
    pub intensity: f64,
    /// The strongest ray's first surface is facility clutter.
    pub clutter: bool,
}

/// The echoes of one ray: (depth, return factor) of the direct echo and
/// of the reflected one, if any, and whether the first surface is clutter.
#[derive(Debug, Clone, Copy)]
struct RayEchoes {
    direct: (f64, f64),
    reflected: Option<(f64, f64)>,
    clutter: bool,
}

impl RayEchoes {
    /// Adds this ray's echoes, weighted by its divergence `weight`, to the
    /// beam's. With an infinite separation the ray's two echoes are merged
    /// first, as seed 004 merges them (one echo per ray, arithmetic
    /// unchanged), else each is kept for the receiver to separate.
    fn add_to(&self, beam: &mut BeamEchoes, weight: f64, separation_m: f64) {
        let (r1, direct) = self.direct;
        let echo = |depth: f64, energy: f64| Echo {
            depth,
            energy: weight * energy,
            clutter: self.clutter,
        };
        match self.reflected {
            None => beam.push(echo(r1, direct)),
            Some((path, reflected)) if separation_m.is_infinite() => {
                let total = direct + reflected;
                if total > 0.0 {
                    beam.push(echo((direct * r1 + reflected * path) / total, total));
                }
            }
            Some((path, reflected)) => {
                beam.push(echo(r1, direct));
                beam.push(echo(path, reflected));
            }
        }
    }
}

/// Everything fixed during one frame.
pub(crate) struct FrameScene<'a> {
    pub target: &'a Target,
    pub motion: TargetMotion<'a>,
    /// Per-material draws of this frame, indexed by `MaterialId`.
    pub surfaces: Vec<Surface>,
    /// Facility background meshes (sensor frame); empty without clutter.
    pub clutter: Vec<Mesh>,
    pub clutter_surface: Surface,
    /// Radius of the sphere about the body origin that holds the target (m).
    pub bounding_radius: f64,
    /// β (rad), or 0 without beam divergence.
    pub beta: f64,
    /// Rays per beam (1 without divergence).
    pub rays_per_beam: usize,
    pub reflections: bool,
    pub max_range: f64,
    /// Echoes farther apart than this are separate returns, and the
    /// strongest is reported (`crate::echoes`); infinite: seed 004's
    /// average of all of them.
    pub echo_separation_m: f64,
    /// Offset of a reflected ray's origin along the surface normal (m), so it
    /// does not hit the face it leaves (`spacepose-model` advises ~1e-4 of
    /// the mesh size for its `f32` BVH).
    pub reflection_offset_m: f64,
}

impl FrameScene<'_> {
    /// Traces the beam emitted along `dir` (unit, sensor frame) at time `t`.
    pub fn trace_beam(&self, t: f64, dir: &Vector3<f64>, rng: &mut ChaCha8Rng) -> Option<BeamEcho> {
        let p = self.motion.position(t);
        let target_possible = self.may_hit_target(&p, dir);
        if !target_possible && self.clutter.is_empty() {
            return None;
        }
        let snap = Snapshot {
            r: if target_possible {
                self.motion.rotation(t)
            } else {
                Rotation3::identity()
            },
            p,
        };
        let mut sum_w = 0.0;
        let mut echoes = BeamEchoes::default();
        let cone = Cone::new(dir);
        for _ in 0..self.rays_per_beam {
            let (ray, weight) = if self.beta > 0.0 {
                // γ ~ U[0, β] about a uniform azimuth, weight of Eq. (18).
                let (ray, gamma) = cone.sample(self.beta, rng);
                (ray, divergence_weight(gamma, self.beta))
            } else {
                (*dir, 1.0)
            };
            sum_w += weight;
            if let Some(ray_echoes) = self.trace_ray(&snap, target_possible, &ray, rng) {
                ray_echoes.add_to(&mut echoes, weight, self.echo_separation_m);
            }
        }
        let detected = echoes.detect(self.echo_separation_m)?;
        Some(BeamEcho {
            depth: detected.depth,
            intensity: detected.energy / sum_w,
            clutter: detected.clutter,
        })
    }

    /// Cheap rejection: can a ray of this beam reach the sphere of radius
    /// `bounding_radius` about the target's centre of mass?
    #[inline]
    fn may_hit_target(&self, p: &Vector3<f64>, dir: &Vector3<f64>) -> bool {
        let along = p.dot(dir);
        let r = self.bounding_radius;
        if along < -r {
            return false;
        }
        let perp2 = (p.norm_squared() - along * along).max(0.0);
        // Divergent rays deviate by at most β from the axis.
        let reach = r + (along.max(0.0) + r) * self.beta.sin() + 1e-6;
        perp2 <= reach * reach
    }

    /// One ray: direct echo, plus one reflected echo in the reflection cone
    /// (seed 004 §IV.A).
    fn trace_ray(
        &self,
        snap: &Snapshot,
        target_possible: bool,
        dir: &Vector3<f64>,
        rng: &mut ChaCha8Rng,
    ) -> Option<RayEchoes> {
        let hit = self.cast_scene(
            snap,
            target_possible,
            &Vector3::zeros(),
            dir,
            self.max_range,
        )?;
        let s = hit.surface;
        let r1 = hit.distance.max(1e-9);
        // Eq. (17) with α = 2θ, times ρ_T.
        let cos1 = -dir.dot(&hit.normal);
        let direct = s.reflectance * phong_backscatter(s.kd, s.eta, cos1) / (r1 * r1);
        let only_direct = RayEchoes {
            direct: (r1, direct),
            reflected: None,
            clutter: hit.clutter,
        };
        if !self.reflections || s.cone_half_angle <= 0.0 {
            return Some(only_direct);
        }
        let (refl, alpha) = sample_cone(&mirror(dir, &hit.normal), s.cone_half_angle, rng);
        if refl.dot(&hit.normal) <= 0.0 {
            return Some(only_direct);
        }
        let origin = dir * r1 + hit.normal * self.reflection_offset_m;
        let Some(hit2) = self.cast_scene(snap, true, &origin, &refl, self.max_range - r1) else {
            return Some(only_direct);
        };
        // Specular lobe of Eq. (17) at the first surface, crossed twice (out
        // and back along the same path), back-scatter at the second one.
        let lobe = s.reflectance * (1.0 - s.kd) * cos_pow(alpha.cos(), s.eta);
        let s2 = hit2.surface;
        let cos2 = -refl.dot(&hit2.normal);
        let path = r1 + hit2.distance;
        let reflected =
            lobe * lobe * s2.reflectance * phong_backscatter(s2.kd, s2.eta, cos2) / (path * path);
        Some(RayEchoes {
            reflected: Some((path, reflected)),
            ..only_direct
        })
    }

    /// Nearest hit of the ray `origin + s dir` (sensor frame) with the target
    /// (at `snap`) and the facility background.
    fn cast_scene(
        &self,
        snap: &Snapshot,
        target_possible: bool,
        origin: &Vector3<f64>,
        dir: &Vector3<f64>,
        max_range: f64,
    ) -> Option<SceneHit> {
        let mut best: Option<SceneHit> = None;
        if target_possible {
            let origin_b = snap.r.inverse_transform_vector(&(origin - snap.p));
            let dir_b = snap.r.inverse_transform_vector(dir);
            if let Some(h) = self.target.cast_ray(&origin_b, &dir_b, max_range) {
                best = Some(SceneHit {
                    distance: h.distance,
                    normal: snap.r * h.normal,
                    surface: self.surfaces[usize::from(h.material)],
                    clutter: false,
                });
            }
        }
        for mesh in &self.clutter {
            let limit = best.as_ref().map_or(max_range, |b| b.distance);
            if let Some(h) = mesh.cast_ray(origin, dir, limit)
                && h.distance < limit
            {
                best = Some(SceneHit {
                    distance: h.distance,
                    normal: h.normal,
                    surface: self.clutter_surface,
                    clutter: true,
                });
            }
        }
        best
    }
}
