"""Exact pixel coverage of screen-space triangles, as row spans.

Vertices arrive snapped to a fixed-point grid (``subpixel_bits`` fraction bits), so every
edge function is an exact int64 and the fill rule decides ties exactly:

- ``top-left`` (spec): a sample exactly on an edge belongs to the triangle only if the edge
  is a top edge (horizontal, interior below) or a left edge (interior to its right). Two
  triangles sharing an edge therefore never both cover, and never both miss, a sample on
  it: a closed mesh covers each pixel exactly once per layer.
- ``inclusive`` (the original device): samples on edges are inside; a triangle whose
  snapped area is zero covers every sample (all its edge functions are zero).

Both windings draw. Each triangle yields, per covered row, the inclusive column span
``[lo, hi]``; :func:`fragments` expands spans into pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Spans:
    """Covered row spans: triangle (position in the input), row, first and last column."""

    tri: np.ndarray
    row: np.ndarray
    lo: np.ndarray
    hi: np.ndarray


def spans(
    x: np.ndarray,
    y: np.ndarray,
    width: int,
    height: int,
    subpixel_bits: int,
    centre: bool = True,
    rule: str = "top-left",
) -> Spans:
    """Coverage of triangles with fixed-point vertices ``x``, ``y`` (T, 3) int64.

    Pixel (i, j) samples at ``(i + 0.5, j + 0.5)`` when ``centre`` else at ``(i, j)``.
    """
    one = np.int64(1) << subpixel_bits
    off = one // 2 if centre else np.int64(0)
    x0, x1, x2 = x[:, 0], x[:, 1], x[:, 2]
    y0, y1, y2 = y[:, 0], y[:, 1], y[:, 2]
    area2 = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)
    # Orient every triangle positively (clockwise on a y-down screen): both windings draw.
    flip = area2 < 0
    x1, x2 = np.where(flip, x2, x1), np.where(flip, x1, x2)
    y1, y2 = np.where(flip, y2, y1), np.where(flip, y1, y2)
    ax = np.stack([x0, x1, x2], axis=1)
    ay = np.stack([y0, y1, y2], axis=1)
    bx = np.stack([x1, x2, x0], axis=1)
    by = np.stack([y1, y2, y0], axis=1)
    dx, dy = bx - ax, by - ay
    if rule == "top-left":
        top_left = (dy < 0) | ((dy == 0) & (dx > 0))
        kmin = np.where(top_left, 0, 1).astype(np.int64)
        live = area2 != 0
    elif rule == "inclusive":
        kmin = np.zeros_like(dx)
        live = np.ones(area2.shape, dtype=bool)
    else:
        raise ValueError(f"unknown fill rule {rule!r}")
    degenerate = area2 == 0
    ymin, ymax = ay.min(axis=1), ay.max(axis=1)
    j_lo = np.maximum(_ceil_div(ymin - off, one), 0)
    j_hi = np.minimum((ymax - off) // one, height - 1)
    if rule == "inclusive":
        j_lo = np.where(degenerate, 0, j_lo)
        j_hi = np.where(degenerate, height - 1, j_hi)
    rows = np.where(live, np.maximum(j_hi - j_lo + 1, 0), 0)
    tri = np.repeat(np.arange(x.shape[0]), rows)
    row = j_lo[tri] + (np.arange(tri.size) - np.repeat(np.cumsum(rows) - rows, rows))
    sy = row * one + off  # sample y of each (triangle, row)
    lo = np.zeros(tri.size, dtype=np.int64)
    hi = np.full(tri.size, width - 1, dtype=np.int64)
    for e in range(3):
        edx, edy = dx[tri, e], dy[tri, e]
        # inside: edx*(sy - ay) - edy*(sx - ax) >= kmin, with sx = i*one + off
        r = kmin[tri, e] - edx * (sy - ay[tri, e]) - edy * (ax[tri, e] - off)
        a = -edy * one  # coefficient of i:  a*i >= r
        pos, neg = a > 0, a < 0
        safe = np.where(a == 0, 1, a)
        lo = np.where(pos, np.maximum(lo, _ceil_div(r, safe)), lo)
        hi = np.where(neg, np.minimum(hi, r // safe), hi)
        none = (a == 0) & (r > 0)
        hi = np.where(none, -1, hi)
    if rule == "inclusive":
        lo = np.where(degenerate[tri], 0, lo)
        hi = np.where(degenerate[tri], width - 1, hi)
    keep = hi >= lo
    return Spans(tri[keep], row[keep], lo[keep], hi[keep])


def fragments(s: Spans) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Expand spans into (span index, column, row) per covered pixel."""
    n = s.hi - s.lo + 1
    span = np.repeat(np.arange(n.size), n)
    col = s.lo[span] + (np.arange(span.size) - np.repeat(np.cumsum(n) - n, n))
    return span, col, s.row[span]


def _ceil_div(a: np.ndarray, b: np.ndarray | np.int64) -> np.ndarray:
    return -((-a) // b)
