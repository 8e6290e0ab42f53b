"""The thesis's ray tracer geometry stage (Chapter 5).

Each pixel's ray runs from the near plane (t = 0) to the far plane (t = 1) of an OpenGL
style perspective projection: the canonical points v0 = (x, y, -1, 1) and
v1 = (x, y, 1, 1) are taken back through the inverse projection (with the division by w)
into camera space (q0, q1) and through the inverse model-view matrix into the octree's
normalised [-1, 1]^3 (p0, p1); o = p0 and d = p1 - p0 (Equations 5.1-5.2). Pixel
centres are used: x = (2*(col + 0.5)/w - 1), y = (1 - 2*(row + 0.5)/h), so row 0 is the
top of the image.

A hit's t maps to two depth conventions: the projection's z (Equations 5.4-5.5, what a
rasterizer's z-buffer holds, in [-1, 1]) and the Euclidean distance from the eye in
camera space (what REND3R frames hold).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import Rend3rError


def perspective(fovy_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    """OpenGL perspective projection matrix (camera looks down -z)."""
    if not (0 < near < far) or not 0 < fovy_deg < 180 or aspect <= 0:
        raise Rend3rError(f"bad projection: fovy {fovy_deg}, aspect {aspect}, near {near}, far {far}")
    f = 1.0 / np.tan(np.radians(fovy_deg) / 2)
    return np.array([[f / aspect, 0, 0, 0],
                     [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]], dtype=np.float64)


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """View matrix placing the camera at ``eye`` looking at ``target``."""
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    fwd = target - eye
    if np.linalg.norm(fwd) == 0:
        raise Rend3rError("camera eye and target coincide")
    fwd /= np.linalg.norm(fwd)
    side = np.cross(fwd, up)
    if np.linalg.norm(side) < 1e-12:
        raise Rend3rError("camera up vector is parallel to the view direction")
    side /= np.linalg.norm(side)
    true_up = np.cross(side, fwd)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = side, true_up, -fwd
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def model_matrix(bounds) -> np.ndarray:
    """Model transform taking the octree's [-1, 1]^3 to the world cube ``bounds``."""
    lo, hi = np.asarray(bounds[:3], dtype=np.float64), np.asarray(bounds[3:], dtype=np.float64)
    m = np.eye(4)
    m[:3, :3] *= (hi - lo) / 2
    m[:3, 3] = (hi + lo) / 2
    return m


@dataclass(frozen=True)
class Camera:
    """A pinhole camera: placement, projection and image size."""

    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    fovy: float = 45.0
    near: float = 0.1
    far: float = 100.0
    width: int = 640
    height: int = 480

    def view(self) -> np.ndarray:
        return look_at(self.eye, self.target, self.up)

    def projection(self) -> np.ndarray:
        return perspective(self.fovy, self.width / self.height, self.near, self.far)


def orbit_camera(bounds, azimuth: float = 35.0, elevation: float = 25.0, distance: float = 1.6,
                 width: int = 640, height: int = 480, fovy: float = 45.0) -> Camera:
    """A camera looking at the centre of ``bounds`` from ``distance`` half-diagonals away."""
    lo, hi = np.asarray(bounds[:3], dtype=np.float64), np.asarray(bounds[3:], dtype=np.float64)
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi - lo)) / 2
    az, el = np.radians(azimuth), np.radians(elevation)
    offset = np.array([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])
    eye = centre + distance * radius * offset
    return Camera(tuple(eye), tuple(centre), (0.0, 1.0, 0.0), fovy,
                  near=0.05 * radius, far=(distance + 2) * radius, width=width, height=height)


@dataclass(frozen=True)
class PrimaryRays:
    """Rays in octree space plus their camera-space end points, all (n, 3), row-major pixels."""

    origin: np.ndarray
    direction: np.ndarray
    q0: np.ndarray
    q1: np.ndarray


def _apply(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    h = np.concatenate([pts, np.ones((len(pts), 1))], 1) @ m.T
    return h[:, :3] / h[:, 3:4]


def primary_rays(cam: Camera, model: np.ndarray) -> PrimaryRays:
    """Equation 5.1: near/far points of every pixel in camera and octree space."""
    w, h = cam.width, cam.height
    if w <= 0 or h <= 0:
        raise Rend3rError(f"bad image size {w}x{h}")
    xs = 2 * (np.arange(w) + 0.5) / w - 1
    ys = 1 - 2 * (np.arange(h) + 0.5) / h
    x, y = np.meshgrid(xs, ys)
    x, y = x.ravel(), y.ravel()
    p_inv = np.linalg.inv(cam.projection())
    q0 = _apply(p_inv, np.stack([x, y, -np.ones_like(x)], 1))
    q1 = _apply(p_inv, np.stack([x, y, np.ones_like(x)], 1))
    mv_inv = np.linalg.inv(cam.view() @ model)
    p0, p1 = _apply(mv_inv, q0), _apply(mv_inv, q1)
    if not (np.all(np.isfinite(p0)) and np.all(np.isfinite(p1))):
        raise Rend3rError("camera or model transform is degenerate (non-finite rays)")
    return PrimaryRays(p0, p1 - p0, q0, q1)


def t_to_ndc_z(rays: PrimaryRays, t: np.ndarray, cam: Camera) -> np.ndarray:
    """Equations 5.4-5.5: the projection's z of the hit at ``t`` (inf where t is inf)."""
    finite = np.isfinite(t)
    tt = np.where(finite, t, 0.0)[:, None]
    qc = rays.q0 + (rays.q1 - rays.q0) * tt
    z = _apply(cam.projection(), qc)[:, 2]
    return np.where(finite, z, np.inf)


def t_to_distance(rays: PrimaryRays, t: np.ndarray) -> np.ndarray:
    """Euclidean eye-to-hit distance in camera space (inf where t is inf)."""
    finite = np.isfinite(t)
    tt = np.where(finite, t, 0.0)[:, None]
    qc = rays.q0 + (rays.q1 - rays.q0) * tt
    return np.where(finite, np.linalg.norm(qc, axis=1), np.inf)
