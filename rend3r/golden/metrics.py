"""Image and provenance metrics for comparing rendered frames.

Colour metrics work on RGB888 (RGB565 frame buffers are widened by bit replication, as
the emulator's PNG writer does); provenance metrics compare which shape each pixel's ray
hit (``-1`` = miss).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..emu.image import rgb565_to_rgb888


def as_rgb888(image: np.ndarray) -> np.ndarray:
    """Accept an (H, W) uint16 RGB565 buffer or an (H, W, 3) uint8 image; return RGB888."""
    a = np.asarray(image)
    if a.ndim == 2 and a.dtype == np.uint16:
        return rgb565_to_rgb888(a)
    if a.ndim == 3 and a.shape[2] == 3 and a.dtype == np.uint8:
        return a
    raise ValueError(f"expected an (H, W) uint16 RGB565 buffer or (H, W, 3) uint8 image, got {a.shape} {a.dtype}")


@dataclass(frozen=True)
class ImageMetrics:
    """How far image B is from reference image A."""

    pixels: int
    differing: int  # pixels with any channel different
    max_channel: int  # largest absolute channel difference, 0..255
    psnr: float  # dB over all channels; inf when identical

    @property
    def share_differing(self) -> float:
        return self.differing / self.pixels if self.pixels else 0.0

    def within(self, max_channel: int | None = None, max_share: float | None = None, min_psnr: float | None = None) -> bool:
        """True when every given bound holds (bounds left as None are not checked)."""
        return (
            (max_channel is None or self.max_channel <= max_channel)
            and (max_share is None or self.share_differing <= max_share)
            and (min_psnr is None or self.psnr >= min_psnr)
        )

    def describe(self) -> str:
        psnr = "inf" if math.isinf(self.psnr) else f"{self.psnr:.2f}"
        return (
            f"max channel difference {self.max_channel}, differing pixels {self.differing}/{self.pixels} "
            f"({100 * self.share_differing:.3f}%), PSNR {psnr} dB"
        )


def image_metrics(a: np.ndarray, b: np.ndarray, mask: np.ndarray | None = None) -> ImageMetrics:
    """Colour metrics of ``b`` against reference ``a`` (RGB565 buffers or RGB888 images),
    over all pixels or only those where the (H, W) boolean ``mask`` is set."""
    x = as_rgb888(a).astype(np.int16)
    y = as_rgb888(b).astype(np.int16)
    if x.shape != y.shape:
        raise ValueError(f"image sizes differ: {x.shape[1]}x{x.shape[0]} vs {y.shape[1]}x{y.shape[0]}")
    if mask is not None:
        x, y = x[mask][None], y[mask][None]
    d = np.abs(x - y)
    pixels = x.shape[0] * x.shape[1]
    differing = int(np.count_nonzero(d.max(axis=-1))) if pixels else 0
    max_channel = int(d.max()) if pixels else 0
    mse = float(np.mean(d.astype(np.float64) ** 2)) if pixels else 0.0
    psnr = math.inf if mse == 0.0 else 10.0 * math.log10(255.0**2 / mse)
    return ImageMetrics(pixels, differing, max_channel, psnr)


@dataclass(frozen=True)
class ProvenanceMetrics:
    """Geometric disagreement of B against reference A, from per-pixel shape indices."""

    pixels: int
    hit_miss: int  # one hit, the other missed (silhouette errors)
    nearest_shape: int  # both hit, but different shapes

    def describe(self) -> str:
        return f"hit/miss differs at {self.hit_miss} pixels, nearest shape differs at {self.nearest_shape} pixels"


def provenance_metrics(a: np.ndarray, b: np.ndarray) -> ProvenanceMetrics:
    """Compare two (H, W) shape-index maps (``-1`` = miss)."""
    pa = np.asarray(a)
    pb = np.asarray(b)
    if pa.shape != pb.shape:
        raise ValueError(f"provenance sizes differ: {pa.shape} vs {pb.shape}")
    hit_a = pa >= 0
    hit_b = pb >= 0
    hit_miss = int(np.count_nonzero(hit_a != hit_b))
    nearest = int(np.count_nonzero(hit_a & hit_b & (pa != pb)))
    return ProvenanceMetrics(pa.size, hit_miss, nearest)


def interior_mask(provenance: np.ndarray) -> np.ndarray:
    """Pixels away from silhouettes: the whole 3x3 neighbourhood is all hit or all miss.

    Border pixels count only the neighbours inside the image.
    """
    hit = np.asarray(provenance) >= 0
    padded_hit = np.pad(hit, 1, mode="edge")
    all_hit = np.ones_like(hit)
    any_hit = np.zeros_like(hit)
    h, w = hit.shape
    for dy in range(3):
        for dx in range(3):
            window = padded_hit[dy : dy + h, dx : dx + w]
            all_hit &= window
            any_hit |= window
    return all_hit | ~any_hit


def region_interior_mask(provenance: np.ndarray) -> np.ndarray:
    """Pixels whose whole 3x3 neighbourhood saw the same shape (or all missed).

    Away from every silhouette, including edges where one shape occludes another, a
    pixel's colour depends only on shading, so colour bounds are meaningful there.
    """
    prov = np.asarray(provenance)
    padded = np.pad(prov, 1, mode="edge")
    h, w = prov.shape
    same = np.ones(prov.shape, dtype=bool)
    for dy in range(3):
        for dx in range(3):
            same &= padded[dy : dy + h, dx : dx + w] == prov
    return same


def diff_image(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """An RGB888 picture of where ``b`` differs from ``a``.

    Unchanged pixels show the reference dimmed to a quarter brightness in grey; changed
    pixels are magenta, brighter the larger the difference (at least half brightness, so a
    one-step difference is still plain to see).
    """
    x = as_rgb888(a)
    y = as_rgb888(b)
    if x.shape != y.shape:
        raise ValueError(f"image sizes differ: {x.shape[1]}x{x.shape[0]} vs {y.shape[1]}x{y.shape[0]}")
    grey = (x.astype(np.uint16).sum(axis=-1) // 12).astype(np.uint8)
    out = np.repeat(grey[..., None], 3, axis=-1)
    d = np.abs(x.astype(np.int16) - y.astype(np.int16)).max(axis=-1)
    changed = d > 0
    level = (128 + (d.astype(np.int32) * 127) // 255).astype(np.uint8)
    out[changed] = np.stack([level, np.zeros_like(level), level], axis=-1)[changed]
    return out
