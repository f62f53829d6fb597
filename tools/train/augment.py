"""Depth-image augmentations of seed 004 §IV.B (Fig. 7), batched in torch and seeded.

- distortion (Fig. 7b): a smooth random displacement field plus a small isotropic scale
  about the image centre (the ROI centre). Nearest-neighbour resampling, so empty pixels
  (0) never blend into depth values. The scale also scales the x,y position label.
  No in-plane rotation: that would rotate the attitude and invalidate the soft label.
- black patches (Fig. 7c): random rectangles set to 0 (missing returns).
- added points (Fig. 7d): isolated pixels with random depth (outliers, ghost returns).
- added surfaces (Fig. 7d): a random elliptic planar patch, inserted with a z-buffer (it
  fills empty pixels and hides what lies behind it), like a reflection or a stray surface.

Every draw comes from the `torch.Generator` given, so a run is reproducible from its seed.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
import torch.nn.functional as F


@dataclass
class AugmentConfig:
    """Probabilities (per image) and magnitudes of each augmentation."""

    p_distort: float = 0.5
    distort_px: float = 1.5        # max displacement of the smooth field, pixels
    distort_grid: int = 4          # control points per side of the displacement field
    scale_range: float = 0.05      # isotropic scale in [1 - r, 1 + r]
    p_patches: float = 0.4
    max_patches: int = 3
    patch_frac: tuple[float, float] = (1 / 16, 1 / 4)  # patch side, fraction of N
    p_points: float = 0.4
    points_density: float = 0.01   # max fraction of pixels turned into outliers
    p_surface: float = 0.3
    surface_frac: tuple[float, float] = (1 / 16, 1 / 4)  # ellipse semi-axis, fraction of N

    def to_dict(self) -> dict:
        return asdict(self)


def _uniform(gen: torch.Generator, shape, lo: float, hi: float) -> torch.Tensor:
    return lo + (hi - lo) * torch.rand(shape, generator=gen)


def _coords(n: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Pixel centres in [-1, 1] (align_corners=False): xx varies along columns."""
    c = (torch.arange(n, dtype=torch.float32) + 0.5) / n * 2 - 1
    return c.view(1, 1, n).expand(1, n, n), c.view(1, n, 1).expand(1, n, n)


def distort(x: torch.Tensor, pos: torch.Tensor, cfg: AugmentConfig,
            gen: torch.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """Smooth warp + isotropic scale of the images [B,1,N,N]; pos [B,3] x,y scaled alike."""
    b, _, n, _ = x.shape
    on = torch.rand(b, generator=gen) < cfg.p_distort
    if not on.any():
        return x, pos
    scale = torch.where(on, _uniform(gen, (b,), 1 - cfg.scale_range, 1 + cfg.scale_range),
                        torch.ones(b))
    g = cfg.distort_grid
    field = _uniform(gen, (b, 2, g, g), -1.0, 1.0) * (cfg.distort_px * 2 / n)
    field = F.interpolate(field, size=(n, n), mode="bicubic", align_corners=True)
    field = field * on.view(b, 1, 1, 1)
    xx, yy = _coords(n)
    base = torch.stack((xx, yy), dim=-1).expand(b, n, n, 2)
    # Output pixel u samples input at u / s: the content grows by s about the centre.
    grid = base / scale.view(b, 1, 1, 1) + field.permute(0, 2, 3, 1)
    out = F.grid_sample(x, grid, mode="nearest", padding_mode="zeros", align_corners=False)
    pos = pos.clone()
    pos[:, :2] *= scale.view(b, 1)
    return out, pos


def black_patches(x: torch.Tensor, cfg: AugmentConfig, gen: torch.Generator) -> torch.Tensor:
    """Zero up to `max_patches` random rectangles in a fraction `p_patches` of the images."""
    b, _, n, _ = x.shape
    k = cfg.max_patches
    on = (torch.rand(b, 1, generator=gen) < cfg.p_patches)
    used = torch.arange(k).view(1, k) < torch.randint(1, k + 1, (b, 1), generator=gen)
    lo, hi = cfg.patch_frac
    w = _uniform(gen, (b, k), lo, hi) * 2
    h = _uniform(gen, (b, k), lo, hi) * 2
    x0 = _uniform(gen, (b, k), -1.0, 1.0) - w / 2
    y0 = _uniform(gen, (b, k), -1.0, 1.0) - h / 2
    xx, yy = _coords(n)
    xx, yy = xx.view(1, 1, n, n), yy.view(1, 1, n, n)

    def v(t: torch.Tensor) -> torch.Tensor:
        return t.view(b, k, 1, 1)

    inside = (xx >= v(x0)) & (xx < v(x0 + w)) & (yy >= v(y0)) & (yy < v(y0 + h))
    mask = (inside & v(used & on)).any(dim=1, keepdim=True)
    return x.masked_fill(mask, 0.0)


def added_points(x: torch.Tensor, cfg: AugmentConfig, gen: torch.Generator) -> torch.Tensor:
    """Set a random sparse set of pixels to random depths in a fraction `p_points`."""
    b, _, n, _ = x.shape
    on = torch.rand(b, 1, 1, 1, generator=gen) < cfg.p_points
    density = _uniform(gen, (b, 1, 1, 1), 0.0, cfg.points_density)
    mask = (torch.rand(b, 1, n, n, generator=gen) < density) & on
    values = _uniform(gen, (b, 1, n, n), 0.05, 0.95)
    return torch.where(mask, values, x)


def added_surface(x: torch.Tensor, cfg: AugmentConfig, gen: torch.Generator) -> torch.Tensor:
    """Insert one planar elliptic patch (z-buffered) in a fraction `p_surface` of the images."""
    b, _, n, _ = x.shape
    on = torch.rand(b, generator=gen) < cfg.p_surface
    if not on.any():
        return x

    def r(lo: float, hi: float) -> torch.Tensor:
        return _uniform(gen, (b, 1, 1, 1), lo, hi)

    lo, hi = cfg.surface_frac
    cx, cy = r(-0.8, 0.8), r(-0.8, 0.8)
    a, c = r(lo, hi) * 2, r(lo / 2, hi / 2) * 2
    ang = r(0.0, 3.14159265)
    depth0, gx, gy = r(0.25, 0.95), r(-0.15, 0.15), r(-0.15, 0.15)
    xx, yy = _coords(n)
    xx, yy = xx.view(1, 1, n, n) - cx, yy.view(1, 1, n, n) - cy
    u = xx * torch.cos(ang) + yy * torch.sin(ang)
    w = -xx * torch.sin(ang) + yy * torch.cos(ang)
    inside = (u / a) ** 2 + (w / c) ** 2 <= 1.0
    plane = (depth0 + gx * xx + gy * yy).clamp(0.01, 1.0)
    # Z-buffer: smaller depth value = nearer the sensor (Eq. 3).
    wins = inside & on.view(b, 1, 1, 1) & ((x == 0) | (plane < x))
    return torch.where(wins, plane, x)


def augment(x: torch.Tensor, pos: torch.Tensor, cfg: AugmentConfig,
            gen: torch.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """All of §IV.B in order: distortion, added surface, added points, black patches."""
    x, pos = distort(x, pos, cfg, gen)
    x = added_surface(x, cfg, gen)
    x = added_points(x, cfg, gen)
    x = black_patches(x, cfg, gen)
    return x.clamp_(0.0, 1.0), pos
