"""Shapes in working precision and the raycaster, in the device's order of operations.

Per shape: translate the ray origin by the negated location, rotate origin and direction
by the inverse quaternion (conj(q) * (0, v) * q), multiply by the inverse scales, then the
quadratic of the shape's normal form (sphere, cylinder, cone), solved as the device does.
Everything is vectorised over (pixel, shape) pairs: arrays hold one entry per pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..isa import Table, lookup
from ..isa.float16 import float_to_bits
from ..isa.tables import SHAPE_TYPE_CODES
from .arith import Arith
from .scene import Scene, prop_index
from .vec import Quat, Vec, madd3, mul3, rotate, rotate_inverse, sub3

#: z-term sign and constant of each shape type's normal form: x^2 + y^2 + zsign*z^2 = one.
NORMAL_FORMS = {SHAPE_TYPE_CODES[name]: form for name, form in (
    ("sphere", (1.0, 1.0)), ("cylinder", (0.0, 1.0)), ("cone", (-1.0, 0.0)))}
SPHERE = SHAPE_TYPE_CODES["sphere"]
_TYPE = lookup(Table.SHAPE, "type")
_ONE = float_to_bits(1.0)


@dataclass(frozen=True)
class Shapes:
    """The shapes that are on, in index order (one entry per shape, or per pair after take)."""

    index: np.ndarray  # program shape index (int64)
    kind: np.ndarray  # shape type code (SHAPE_TYPES)
    loc: Vec
    rot: Quat
    inv_scale: Vec
    zsign: np.ndarray  # +1, 0, -1: how the z term enters the quadratic
    one: np.ndarray  # 1 or 0: the constant of the normal form
    color: np.ndarray  # RGB565, uint16

    def __len__(self) -> int:
        return len(self.index)

    def take(self, sel: np.ndarray | int) -> "Shapes":
        """The shapes at positions ``sel`` (e.g. one entry per pixel-shape pair; an int
        gives scalar values)."""
        t = lambda a: a[sel]  # noqa: E731
        return Shapes(
            t(self.index), t(self.kind), tuple(map(t, self.loc)), tuple(map(t, self.rot)),
            tuple(map(t, self.inv_scale)), t(self.zsign), t(self.one), t(self.color),
        )


def shapes_from_scene(scene: Scene, arith: Arith) -> Shapes:
    """Collect the shapes whose type is sphere, cylinder or cone (others are off)."""
    p = {n: prop_index(Table.SHAPE, n) for n in (
        "xloc", "yloc", "zloc", "rrot", "irot", "jrot", "krot", "xscl", "yscl", "zscl", "col", "type")}
    objects = scene.objects
    on = np.isin(objects.values[:, p["type"]] & _TYPE.value_mask, list(NORMAL_FORMS))
    table = objects.values[on]

    def bits(name: str) -> np.ndarray:
        return table[:, p[name]].copy()

    kind = bits("type") & _TYPE.value_mask
    rot = [bits(n) for n in ("rrot", "irot", "jrot", "krot")]
    unset = (rot[0] | rot[1] | rot[2] | rot[3]) & 0x7FFF == 0  # all-zero quaternion: identity
    rot[0] = np.where(unset, np.uint16(_ONE), rot[0])
    forms = np.array([NORMAL_FORMS.get(int(k), (0.0, 0.0)) for k in range(_TYPE.value_mask + 1)])
    return Shapes(
        index=objects.index[on],
        kind=kind.astype(np.uint8),
        loc=tuple(arith.from_bits(bits(a)) for a in ("xloc", "yloc", "zloc")),
        rot=tuple(arith.from_bits(b) for b in rot),
        inv_scale=tuple(arith.from_bits(bits(a)) for a in ("xscl", "yscl", "zscl")),
        zsign=forms[kind, 0].astype(arith.dtype),
        one=forms[kind, 1].astype(arith.dtype),
        color=bits("col"),
    )


def to_object(ar: Arith, s: Shapes, point: Vec | None, direction: Vec | None) -> tuple[Vec | None, Vec | None]:
    """A ray's origin and direction in each shape's normal space (either may be None)."""
    S = mul3(ar, rotate_inverse(ar, s.rot, sub3(ar, point, s.loc)), s.inv_scale) if point is not None else None
    D = mul3(ar, rotate_inverse(ar, s.rot, direction), s.inv_scale) if direction is not None else None
    return S, D


@dataclass(frozen=True)
class Form:
    """Just the normal form of shapes (how the z term enters), for pair batches."""

    zsign: np.ndarray


def _zterm(s: Shapes | Form, p: np.ndarray) -> np.ndarray:
    """The z product as the shape type uses it: kept, dropped (0) or negated."""
    if np.ndim(s.zsign) == 0:  # one normal form for every pair (e.g. all spheres)
        if s.zsign == 1:
            return p
        if s.zsign == 0:
            return np.zeros_like(p)
    with np.errstate(invalid="ignore"):
        return np.where(s.zsign == 0, np.zeros((), p.dtype), p * s.zsign)


def uniform_form(s: Shapes) -> Form | None:
    """The shapes' common normal form as a scalar :class:`Form`, or None if they differ."""
    z = s.zsign
    return Form(z[0]) if len(z) and (z == z[0]).all() else None


def origin_term(ar: Arith, s: Shapes, S: Vec) -> np.ndarray:
    """c2 = 2*((Sx^2 + Sy^2) + (z term - one)): depends on the origin only."""
    xy = ar.add(ar.mul(S[0], S[0]), ar.mul(S[1], S[1]))
    h = ar.add(xy, ar.sub(_zterm(s, ar.mul(S[2], S[2])), s.one))
    return ar.add(h, h)


@dataclass(frozen=True)
class Solution:
    """Per pair: accepted hit, its t, whether any value was NaN or infinite, and the
    solver's intermediate values (for tests and hardware comparison)."""

    hit: np.ndarray
    t: np.ndarray
    bad: np.ndarray
    a2: np.ndarray
    b: np.ndarray
    disc: np.ndarray
    root: np.ndarray
    t1: np.ndarray
    t2: np.ndarray


def _finite(*arrays: np.ndarray) -> np.ndarray:
    ok = np.isfinite(arrays[0])
    for a in arrays[1:]:
        ok &= np.isfinite(a)
    return ok


def direction_term(ar: Arith, s: Shapes | Form, D: Vec) -> np.ndarray:
    """a2 = 2*((Dx^2 + Dy^2) + z term): depends on the direction only."""
    dd = ar.add(ar.add(ar.mul(D[0], D[0]), ar.mul(D[1], D[1])), _zterm(s, ar.mul(D[2], D[2])))
    return ar.add(dd, dd)


def solve(ar: Arith, s: Shapes | Form, S: Vec, D: Vec, c2: np.ndarray, tmin: np.ndarray, tmax: np.ndarray,
          a2: np.ndarray | None = None) -> Solution:
    """The quadratic a2/2 t^2 + b t + c2/2 = 0, nearest root t >= tmin (and > 0), t <= tmax.

    ``c2`` (origin term) and ``a2`` (direction term, computed here when None) may come
    from tables shared by many pairs: the same operations on the same inputs.
    """
    if a2 is None:
        a2 = direction_term(ar, s, D)
    ds = ar.add(ar.add(ar.mul(D[0], S[0]), ar.mul(D[1], S[1])), _zterm(s, ar.mul(D[2], S[2])))
    b = ar.add(ds, ds)
    disc = discriminant(ar, b, a2, c2)
    real = disc >= 0
    root, t1, t2 = roots(ar, b, np.where(real, disc, np.zeros((), disc.dtype)), a2)
    # disc = b*b - a2*c2 is finite exactly when a2, b, c2 and disc all are (an infinite or
    # NaN input makes a product infinite or NaN, and the difference with it)
    bad = ~np.isfinite(disc) | (real & ~_finite(t1, t2))
    if np.ndim(tmin) == 0:  # accepted: t > 0 and t >= tmin, which a scalar tmin makes one test
        above = (lambda v: v >= tmin) if tmin > 0 else (lambda v: v > 0)
    else:
        above = lambda v: (v > 0) & (v >= tmin)  # noqa: E731
    ok1, ok2 = real & above(t1), real & above(t2)
    t = np.where(ok1, t1, t2)
    hit = ok1 | ok2
    if not (np.ndim(tmax) == 0 and tmax == np.inf):  # t <= inf holds for every accepted, finite t
        hit &= t <= tmax
    hit &= ~bad
    return Solution(hit, t, bad, a2, b, disc, root, t1, t2)


def discriminant(ar: Arith, b: np.ndarray, a2: np.ndarray, c2: np.ndarray) -> np.ndarray:
    """b*b - a2*c2 (its own stage, rend3r.precision.stages)."""
    return ar.sub(ar.mul(b, b), ar.mul(a2, c2))


def roots(ar: Arith, b: np.ndarray, disc: np.ndarray, a2: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """sqrt(disc) (disc made 0 where negative by the caller), (-b - root)/a2, (-b + root)/a2."""
    root = ar.sqrt(disc)
    nb = ar.neg(b)
    return root, ar.div(ar.sub(nb, root), a2), ar.div(ar.add(nb, root), a2)


def transform_classes(s: Shapes) -> tuple[np.ndarray, np.ndarray]:
    """Shapes sharing rotation, inverse scales and type map a direction identically.

    Returns (one representative position per class, class of each shape).
    """
    parts = [np.asarray(c, np.float64) for c in (*s.rot, *s.inv_scale)] + [s.kind.astype(np.float64)]
    key = np.stack(parts, axis=1)
    _, first, cls = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return first, cls.reshape(-1)


def surface(ar: Arith, s: Shapes | None, S: Vec | None, D: Vec | None, t: np.ndarray, origin: Vec, direction: Vec,
            normals: bool = True) -> tuple[Vec, Vec | None]:
    """World hit point origin + t*d, and world normal (object normal scaled, rotated by q;
    None when ``normals`` is false: unlit scenes need none)."""
    point = madd3(ar, origin, t, direction)
    if not normals:
        return point, None
    P = madd3(ar, S, t, D)
    normal_obj = (P[0], P[1], _zterm(s, P[2]))
    normal = rotate(ar, s.rot, mul3(ar, normal_obj, s.inv_scale))
    return point, normal


def squared_distance(ar: Arith, dd_world: np.ndarray, t: np.ndarray) -> np.ndarray:
    """|d|^2 * t^2 in world space."""
    return ar.mul(dd_world, ar.mul(t, t))


