"""Primary rays: the spec camera (paper) and the device's fixed camera.

Both return :class:`Rays` in working precision, one ray per pixel in row-major order
(flat index ``y * width + x``). See ``docs/emulator.md`` for the camera model.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property, lru_cache

import numpy as np

from ..isa import Table
from .arith import Arith
from .options import EmuOptions
from .scene import Scene, prop_index
from .vec import Quat, Vec, rotate

#: The device's ray generator: start values and the step added once per pixel (float16 bits).
DEVICE_X0, DEVICE_Y0, DEVICE_Z, DEVICE_STEP = 0xC4FD, 0xC37B, 0xBC00, 0x2500
#: Default viewport of the paper: 10 x 7.5 at near-clip 1.
VIEW_WIDTH, VIEW_HEIGHT = 10.0, 7.5


@dataclass(frozen=True)
class Rays:
    """Rays from one origin: ``origin + t * direction`` accepted for ``tmin <= t <= tmax``.

    Pixel (x, y) looks along (xs[x], ys[y], z), turned by ``rotation`` (q * (0, v) *
    conj(q), in working precision) when the camera has one.
    """

    origin: Vec  # three 0-d arrays
    xs: np.ndarray  # (width,)
    ys: np.ndarray  # (height,)
    z: np.ndarray  # 0-d
    rotation: Quat | None
    tmin: np.ndarray
    tmax: np.ndarray
    arith: Arith

    @property
    def grid(self) -> Vec | None:
        """(xs, ys, z) when the directions are exactly (x[column], y[row], z), else None."""
        return (self.xs, self.ys, self.z) if self.rotation is None else None

    def fresh(self) -> Rays:
        """A copy that shares the arrays but not ``direction`` once computed (a shallow
        copy of the fields, without copy.copy's reduce protocol)."""
        rays = object.__new__(Rays)
        fields = rays.__dict__
        fields.update(self.__dict__)
        fields.pop("direction", None)
        return rays

    @cached_property
    def direction(self) -> Vec:
        """Every pixel's direction, row-major: three (pixels,) arrays."""
        shape = (len(self.ys), len(self.xs))
        cam = (np.broadcast_to(self.xs[None, :], shape).ravel(), np.broadcast_to(self.ys[:, None], shape).ravel(),
               np.full(shape[0] * shape[1], self.z, dtype=self.arith.dtype))
        return cam if self.rotation is None else rotate(self.arith, self.rotation, cam)


#: The camera properties the rays depend on.
_RAY_PROPS = ("xloc", "yloc", "zloc", "rrot", "irot", "jrot", "krot", "nclip", "hfov", "vfov", "fclip")


def camera_rays(scene: Scene, options: EmuOptions, arith: Arith) -> Rays:
    """The primary rays of the frame, by the camera model the options select. The same
    camera gives the same rays, so the last few cameras' axes and terms are kept for the
    frames and runs after (read-only arrays); each call gets its own Rays, so a frame's
    per-pixel ``direction`` goes with it."""
    return _rays(*camera_key(scene, options, arith)).fresh()


def camera_key(scene: Scene, options: EmuOptions, arith: Arith) -> tuple:
    """What the frame's rays depend on: equal keys give equal rays (camera_rays)."""
    bits = tuple(scene.camera.get(i, 0) for i in _ray_props())
    return bits, options.camera, options.width, options.height, arith


@lru_cache(maxsize=1)
def _ray_props() -> tuple[int, ...]:
    """The camera table's indices of _RAY_PROPS."""
    return tuple(prop_index(Table.CAMERA, n) for n in _RAY_PROPS)


@lru_cache(maxsize=8)
def _rays(bits: tuple[int, ...], model: str, width: int, height: int, arith: Arith) -> Rays:
    """camera_rays for the camera properties' bits (in _RAY_PROPS order)."""
    cam = dict(zip(_RAY_PROPS, bits))
    origin = tuple(arith.from_bits(cam[n]) for n in ("xloc", "yloc", "zloc"))
    if model == "device":
        rays = _device_rays(origin, width, height, arith)
    else:
        rays = _spec_rays(cam, origin, width, height, arith)
    for a in (rays.xs, rays.ys, rays.z, rays.tmin, rays.tmax, *rays.origin, *(rays.rotation or ())):
        if isinstance(a, np.ndarray):
            a.flags.writeable = False
    return rays


@lru_cache(maxsize=16)
def _device_axis(arith: Arith, start: int, count: int) -> np.ndarray:
    """start, start+step, ...: each value one float16 addition after the previous one."""
    step = arith.from_bits(DEVICE_STEP)
    out = np.empty(count, dtype=arith.dtype)
    v = arith.from_bits(start)
    for i in range(count):
        out[i] = v
        v = arith.add(v, step)
    out.flags.writeable = False
    return out


def _device_rays(origin: Vec, width: int, height: int, arith: Arith) -> Rays:
    """Direction (x0 + x*step, y0 + y*step, -1), unnormalised; row 0 is world y = -3.74."""
    xs = _device_axis(arith, DEVICE_X0, width)
    ys = _device_axis(arith, DEVICE_Y0, height)
    return Rays(origin, xs, ys, arith.from_bits(DEVICE_Z), None, arith.const(0.0), arith.const(np.inf), arith)


def camera_value(scene: Scene, name: str, arith: Arith, default: float) -> np.ndarray:
    """A camera property's value; zero (as memory starts) means the default."""
    return _value(scene.camera_bits(name), arith, default)


def _value(bits: int, arith: Arith, default: float) -> np.ndarray:
    v = arith.from_bits(bits)
    return arith.const(default) if float(v) == 0.0 else v


def camera_quaternion(scene: Scene, arith: Arith) -> Quat | None:
    """The camera's rotation, normalised; None for no rotation (i = j = k = 0, which
    includes the all-zero quaternion of unset memory)."""
    return _quaternion([scene.camera_bits(n) for n in ("rrot", "irot", "jrot", "krot")], arith)


def _quaternion(bits: list[int], arith: Arith) -> Quat | None:
    q = [arith.from_bits(b) for b in bits]
    if all(float(c) == 0.0 for c in q[1:]):
        return None
    r, i, j, k = q
    norm2 = arith.add(arith.add(arith.mul(r, r), arith.mul(i, i)), arith.add(arith.mul(j, j), arith.mul(k, k)))
    norm = arith.sqrt(norm2)
    return tuple(arith.div(c, norm) for c in q)


def exact_viewport_axes(width: int, height: int) -> tuple[list[Fraction], list[Fraction]]:
    """The viewport coordinates of pixel centres as exact rationals: x right, y up."""
    half = Fraction(1, 2)
    ux = [Fraction(VIEW_WIDTH) * (Fraction(2 * x + 1, 2 * width) - half) for x in range(width)]
    uy = [Fraction(VIEW_HEIGHT) * (half - Fraction(2 * y + 1, 2 * height)) for y in range(height)]
    return ux, uy


@lru_cache(maxsize=16)
def _viewport_axes(arith: Arith, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Default viewport coordinates of pixel centres: x right, y up.

    fp64 entries are the exact values rounded once; fp16 and fp32 entries are computed in
    float64 and rounded to the working format (their goldens depend on these bits).
    """
    if arith.precision == "fp64":
        ux, uy = (np.array([float(v) for v in axis], dtype=np.float64) for axis in exact_viewport_axes(width, height))
    else:
        x = (np.arange(width) + 0.5) / width - 0.5
        y = 0.5 - (np.arange(height) + 0.5) / height
        ux, uy = arith.round(VIEW_WIDTH * x), arith.round(VIEW_HEIGHT * y)
    ux.flags.writeable = uy.flags.writeable = False
    return ux, uy


def _spec_rays(cam: dict[str, int], origin: Vec, width: int, height: int, arith: Arith) -> Rays:
    """Camera space (ux*hfov*n, uy*vfov*n, -n) rotated by q; t = 1 is the near plane
    (cam: the camera properties' bits by name)."""
    near = _value(cam["nclip"], arith, 1.0)
    hfov = _value(cam["hfov"], arith, 1.0)
    vfov = _value(cam["vfov"], arith, 1.0)
    ux, uy = _viewport_axes(arith, width, height)
    cx = arith.mul(arith.mul(ux, hfov), near)
    cy = arith.mul(arith.mul(uy, vfov), near)
    far = arith.from_bits(cam["fclip"])
    tmax = arith.const(np.inf) if float(far) == 0.0 else arith.div(far, near)
    rotation = _quaternion([cam[n] for n in ("rrot", "irot", "jrot", "krot")], arith)
    return Rays(origin, cx, cy, arith.neg(near), rotation, arith.const(1.0), tmax, arith)
