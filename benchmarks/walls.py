"""The benchmark scenes: sphere walls that fill the view and render correctly in float16.

A k x k front layer of spheres in front of the spec camera (eye at the origin looking along
-z, hfov = vfov = 0.2: a 90 x 73 degree view, near plane NEAR), 10 units away, spanning
the view's width, each sphere's radius 0.45 of the spacing; one directional light
travelling along (-0.3, -0.4, -1). Behind each front sphere stands a column of
``depth - 1`` more spheres on the eye ray through its centre, spaced geometrically from
BEHIND to FAR times the front distance, each scaled with its distance and then by SHRINK:
hidden behind the front sphere, as seen from the eye and from the light.

Why these walls (docs/performance.md has the measurements):
- Not a 16 x 16 or 256 x 256 visible wall: a sphere that spans 1/k of a 90-degree view
  has |S| of about 4.4 k in normal space, and the device's float16 c = |S|^2 - 1 carries
  an error of |S|^2 * 2**-11; at k = 16 that moves silhouettes by a tenth of the radius
  and the device draws halos several pixels wide. Timing those frames measures a broken
  picture.
- Radii of the stacked spheres at most 8 and NEAR at least the front radius: the ray direction in a sphere's
  normal space (world direction over radius) then stays near 1 or above, so its squared
  components do not flush to zero in float16 (they did with radius 16: a2 20% off and
  false hits in the gaps).
- A 2 x 2 front layer: float16's bounds are loose (a ray may be reported to meet a
  sphere up to about sqrt(24 u) |S| radii from its centre, u = 2**-11), so every hidden
  sphere's cone of candidate rays is about 0.18 rad wide whatever its size. Behind a 4 x 4
  layer (spheres 0.15-0.21 rad across) those cones reach past the front silhouettes and
  rays there test whole columns; behind 2 x 2 (0.38 rad) they stay inside.

bench_raytrace.py and bench_peer.py check every frame with fp16_faithful: the fp16 frame
shows the same shape as fp64's at every pixel farther than BAND pixels from an fp64
silhouette. The same spheres, as arrays, feed the peer renderer (peer_mitsuba.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rend3r.isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, encode, lookup
from rend3r.isa.float16 import float_to_bits

#: spheres -> (k, depth): a k x k front layer, depth layers deep.
LAYOUT = {1: (1, 1), 16: (2, 4), 256: (2, 64), 4096: (2, 1024), 65536: (2, 16384)}
#: near plane per front-layer width k (at least the front radius, below the front surface).
NEAR = {1: 0.5, 2: 5.0}
FOV = 0.2
DISTANCE = 10.0
RADIUS = 0.45  # of the spacing
BEHIND = 2.0  # the first hidden sphere of a column, in front distances
FAR = 4.0  # the last one (radius <= 8: see above)
SHRINK = 0.3  # the hidden spheres' angular radius, of the front sphere's
BAND = 2  # pixels either side of a silhouette where float16 may differ from fp64
LIGHT = (-0.3, -0.4, -1.0)  # the direction the light travels (REND3R's forward vector)
POINT_LIGHT = (3.0, 4.0, 10.0)  # a point light's place: up, right and behind the eye, lighting the same faces


@dataclass(frozen=True)
class Wall:
    """One benchmark scene: the program and the same spheres as arrays."""

    words: np.ndarray  # uint32 program: nr, camera, light (optional), spheres, nf, er
    centers: np.ndarray  # (n, 3) float64, the float16 values the program holds
    radii: np.ndarray  # (n,) float64: 1 / the inverse scale the program holds
    rgb565: np.ndarray  # (n,) uint16
    fov: float = FOV
    light: tuple[float, float, float] = LIGHT

    @property
    def colors(self) -> np.ndarray:
        """Linear reflectance in [0, 1] per channel (for the peer renderer)."""
        c = self.rgb565.astype(np.int64)
        return np.stack([(c >> 11 & 31) / 31, (c >> 5 & 63) / 63, (c & 31) / 31], axis=1)


def _f16(value: float) -> float:
    return float(np.float16(value))


def _prop(table: Table, name: str) -> int:
    return lookup(table, name).index


def wall(n: int, lights: int = 1, point: bool = False) -> Wall:
    """The ``n``-sphere scene (a key of LAYOUT), with 0 or 1 lights: directional, or a point
    light at POINT_LIGHT (its shadow rays head back past the eye; the hidden spheres lie
    behind every origin, along the rays' lines)."""
    k, depth = LAYOUT[n]
    spacing = 10 * FOV * DISTANCE / k
    i, j, d = (a.ravel() for a in np.meshgrid(np.arange(k), np.arange(k), np.arange(depth), indexing="ij"))
    scale = np.where(d > 0, BEHIND * (FAR / BEHIND) ** ((d - 1) / max(1, depth - 2)), 1.0)  # over DISTANCE
    front = np.stack([(i - (k - 1) / 2) * spacing, (j - (k - 1) / 2) * spacing, np.full(i.shape, -DISTANCE)], axis=1)
    centers = np.vectorize(_f16)(front * scale[:, None])
    radii = RADIUS * spacing * scale * np.where(d > 0, SHRINK, 1.0)
    inv = np.vectorize(_f16)(1.0 / radii)
    top = max(1, k - 1)
    rgb565 = ((i * 31 // top) << 11 | (j * 63 // top) << 5 | (31 - d * 31 // max(1, depth - 1))).astype(np.uint16)
    words = list(encode(FrameOp(Func.NR)))
    for name, value in (("rrot", 1.0), ("hfov", FOV), ("vfov", FOV), ("nclip", NEAR[k])):
        words += encode(CameraSet(_prop(Table.CAMERA, name), float_to_bits(value)))
    if lights:
        place = (("src", 2), *((n, float_to_bits(v)) for n, v in zip(("xloc", "yloc", "zloc"), POINT_LIGHT)))
        aim = (("src", 1), *((n, float_to_bits(v)) for n, v in zip(("xfor", "yfor", "zfor"), LIGHT)))
        for name, value in (*(place if point else aim), ("col", 0xFFFF), ("int", float_to_bits(1.0))):
            words += encode(LightSet(0, _prop(Table.LIGHT, name), value))
    p = lambda name: _prop(Table.SHAPE, name)  # noqa: E731
    for s, (c, col, v) in enumerate(zip(centers, rgb565, inv)):
        for (a, va), (b, vb) in ((("type", 1), ("col", int(col))),
                                 (("xloc", float_to_bits(c[0])), ("yloc", float_to_bits(c[1]))),
                                 (("zloc", float_to_bits(c[2])), ("rrot", float_to_bits(1.0))),
                                 (("xscl", float_to_bits(v)), ("yscl", float_to_bits(v))),
                                 (("zscl", float_to_bits(v)), ("mat", 0))):
            words += encode(ShapeSet(s, p(a), p(b), va, vb))
    words += encode(FrameOp(Func.NF)) + encode(FrameOp(Func.ER))
    return Wall(np.array(words, dtype=np.uint32), centers, 1.0 / inv, rgb565)


def silhouette(provenance: np.ndarray, band: int = BAND) -> np.ndarray:
    """Pixels within ``band`` pixels (horizontally, vertically or diagonally) of a pixel
    whose 4-neighbourhood shows more than one shape (or a shape and a miss)."""
    p = np.pad(provenance, 1, mode="edge")
    centre = p[1:-1, 1:-1]
    edge = ((p[:-2, 1:-1] != centre) | (p[2:, 1:-1] != centre) | (p[1:-1, :-2] != centre)
            | (p[1:-1, 2:] != centre))
    h, w = edge.shape
    e = np.pad(edge, band)
    near = np.zeros_like(edge)
    for dy in range(2 * band + 1):
        for dx in range(2 * band + 1):
            near |= e[dy:dy + h, dx:dx + w]
    return near


def fp16_faithful(fp16: np.ndarray, fp64: np.ndarray) -> tuple[bool, int, int]:
    """Whether an fp16 frame's provenance matches fp64's everywhere but near silhouettes:
    (faithful, pixels that differ, of which farther than BAND from a silhouette)."""
    differ = fp16 != fp64
    off = differ & ~silhouette(fp64)
    return not off.any(), int(differ.sum()), int(off.sum())
