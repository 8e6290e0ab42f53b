"""The benchmark scenes' own checks: walls that stay in float16's range, and the
silhouette test that decides whether an fp16 frame may be timed."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import walls  # noqa: E402


def test_silhouette_band_reaches_band_pixels_from_an_edge():
    provenance = np.full((9, 12), -1, np.int32)
    provenance[:, 6:] = 3
    near = walls.silhouette(provenance, band=2)
    assert near[:, 3:9].all()  # the edge pixels (columns 5 and 6) and two either side
    assert not near[:, :3].any() and not near[:, 9:].any()


def test_fp16_faithful_allows_silhouette_differences_only():
    fp64 = np.full((20, 20), -1, np.int32)
    fp64[5:15, 5:15] = 0
    halo = fp64.copy()
    halo[4, 5:15] = 0  # one pixel outside the edge: within the band
    assert walls.fp16_faithful(halo, fp64) == (True, 10, 0)
    broken = fp64.copy()
    broken[10, 10] = -1  # a hole in the middle of the shape
    assert walls.fp16_faithful(broken, fp64) == (False, 1, 1)


def test_walls_hold_the_sizes_their_layout_promises_in_float16_range():
    for n in walls.LAYOUT:
        wall = walls.wall(n, lights=1)
        assert len(wall.centers) == len(wall.radii) == n
        assert np.isfinite(wall.centers).all() and (np.abs(wall.centers) < 65504).all()
        k, depth = walls.LAYOUT[n]
        hidden = wall.radii.reshape(k * k, depth)[:, 1:]
        assert (hidden <= 8).all()  # stacked radii keep the normal-space direction clear of ftz
        assert walls.NEAR[k] < walls.DISTANCE - wall.radii[0]  # the near plane lies before the front surface
