"""A rendered frame: RGB565 pixels, depth and provenance."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Frame:
    """One frame as the frame buffer holds it, with per-pixel depth and provenance."""

    number: int
    rgb565: np.ndarray  # (H, W) uint16
    depth: np.ndarray  # (H, W) float32 distance along the ray; inf where no shape
    provenance: np.ndarray  # (H, W) int32 shape index; -1 where no shape
