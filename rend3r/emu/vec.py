"""Vector and quaternion operations in the device's order, on any :class:`Arith`.

Vectors are 3-tuples and quaternions ``(r, i, j, k)`` 4-tuples of arrays (or 0-d arrays),
so each component broadcasts over pixels and shapes independently.
"""

from __future__ import annotations

import numpy as np

from .arith import Arith

Vec = tuple[np.ndarray, np.ndarray, np.ndarray]
Quat = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def dot(ar: Arith, a: Vec, b: Vec) -> np.ndarray:
    """((x*x' + y*y') + z*z')."""
    return ar.add(ar.add(ar.mul(a[0], b[0]), ar.mul(a[1], b[1])), ar.mul(a[2], b[2]))


def sub3(ar: Arith, a: Vec, b: Vec) -> Vec:
    return (ar.sub(a[0], b[0]), ar.sub(a[1], b[1]), ar.sub(a[2], b[2]))


def mul3(ar: Arith, a: Vec, b: Vec) -> Vec:
    """Componentwise product (scaling by per-axis factors)."""
    return (ar.mul(a[0], b[0]), ar.mul(a[1], b[1]), ar.mul(a[2], b[2]))


def madd3(ar: Arith, origin: Vec, t: np.ndarray, d: Vec) -> Vec:
    """origin + t*d, each component one multiply then one add."""
    return (ar.add(origin[0], ar.mul(t, d[0])), ar.add(origin[1], ar.mul(t, d[1])), ar.add(origin[2], ar.mul(t, d[2])))


def hamilton(ar: Arith, a: Quat, b: Quat, real: bool = True) -> Quat:
    """Hamilton product a*b with the device's pairwise sums.

    ``real=False`` skips the real part (returned as None) when only the vector part is used.
    """
    m = ar.mul
    r = ar.sub(ar.sub(m(a[0], b[0]), m(a[1], b[1])), ar.add(m(a[2], b[2]), m(a[3], b[3]))) if real else None
    i = ar.add(ar.add(m(a[0], b[1]), m(a[1], b[0])), ar.sub(m(a[2], b[3]), m(a[3], b[2])))
    j = ar.add(ar.sub(m(a[0], b[2]), m(a[1], b[3])), ar.add(m(a[2], b[0]), m(a[3], b[1])))
    k = ar.sub(ar.add(m(a[0], b[3]), m(a[1], b[2])), ar.sub(m(a[2], b[1]), m(a[3], b[0])))
    return (r, i, j, k)


def conj(ar: Arith, q: Quat) -> Quat:
    return (q[0], ar.neg(q[1]), ar.neg(q[2]), ar.neg(q[3]))


def hamilton_pure(ar: Arith, a: Quat, v: Vec) -> Quat:
    """a * (0, v): :func:`hamilton` with b0 = 0, bit for bit.

    The products with b0 are signed zeros, and adding or subtracting a signed zero to an
    already rounded value is exact, so those eight steps need no rounding (plain IEEE
    arithmetic gives the same bits, signs of zero included).
    """
    m = ar.mul
    with np.errstate(invalid="ignore"):
        z = [np.multiply(c, np.zeros((), ar.dtype)) for c in a]  # a_k * b0
        r = ar.sub(np.subtract(z[0], m(a[1], v[0])), ar.add(m(a[2], v[1]), m(a[3], v[2])))
        i = ar.add(np.add(m(a[0], v[0]), z[1]), ar.sub(m(a[2], v[2]), m(a[3], v[1])))
        j = ar.add(ar.sub(m(a[0], v[1]), m(a[1], v[2])), np.add(z[2], m(a[3], v[0])))
        k = ar.sub(ar.add(m(a[0], v[2]), m(a[1], v[1])), np.subtract(m(a[2], v[0]), z[3]))
    return (r, i, j, k)


def rotate_inverse(ar: Arith, q: Quat, v: Vec) -> Vec:
    """World to object: conj(q) * (0, v) * q (scaled by |q|^2 when q is not unit)."""
    if _is_identity(q) and _plain(ar, v):
        return v
    w = hamilton(ar, hamilton_pure(ar, conj(ar, q), v), q, real=False)
    return (w[1], w[2], w[3])


def rotate(ar: Arith, q: Quat, v: Vec) -> Vec:
    """Object to world: q * (0, v) * conj(q)."""
    if _is_identity(q) and _plain(ar, v):
        return v
    w = hamilton(ar, hamilton_pure(ar, q, v), conj(ar, q), real=False)
    return (w[1], w[2], w[3])


def _is_identity(q: Quat) -> bool:
    """Whether q is exactly (1, +0, +0, +0) (in every entry, for arrays)."""
    r, *ijk = (np.asarray(c) for c in q)
    return bool((r == 1).all()) and all(bool(((c == 0) & ~np.signbit(c)).all()) for c in ijk)


def _plain(ar: Arith, v: Vec) -> bool:
    """Whether every component of v is a working-precision value (the arith's dtype, as
    every arith result is), finite and at least the smallest normal number in magnitude.

    Then both rotations by exactly (1, +0, +0, +0) return v itself, bit for bit: every
    product with a zero component of q is a signed zero, every sum adds a signed zero to
    x, y or z (or two signed zeros to each other) and leaves the nonzero value as it is,
    and no rounding or flush changes a value that is already in the working format and
    normal. Zeros, subnormals, infinities and NaN take the full computation (their signs
    and NaNs depend on it).
    """
    return all(np.asarray(c).dtype == ar.dtype and bool((np.isfinite(c) & (np.abs(c) >= ar.tiny)).all()) for c in v)
