"""On which side of a float64 result the exact result lies: error-free transformations.

Each function returns ``sign(exact - r)`` (int8: -1, 0, +1) for ``r`` the float64 result of
one operation on float64 operands. The operands are first scaled by powers of two to
significands in [0.25, 2) (``frexp``), so no product below overflows or underflows, even
where ``r`` itself is a float64 subnormal; scaling is exact, and so is everything after it:

- sum: TwoSum (Knuth): ``a + b - s`` is exactly ``(a - (s - bb)) + (b - bb)``, ``bb = s - a``.
- product: Dekker's TwoProduct: splitting each factor into two 26-bit halves (Veltkamp,
  ``c = (2**27 + 1) x``) makes every partial product exact, so ``x y = p + e`` exactly.
- quotient ``q = a / b``: ``a - q b`` from TwoProduct(q, b); ``a - p`` is exact (Sterbenz:
  ``p`` is within a factor 2 of ``a``), and the sign of ``(a - p) - e`` is that of the sum.
- square root ``r = sqrt(a)``: ``a - r r`` the same way.
"""

from __future__ import annotations

import numpy as np

_SPLITTER = 134217729.0  # 2**27 + 1


def _sign(x: np.ndarray) -> np.ndarray:
    return np.sign(x).astype(np.int8)


def _split(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = _SPLITTER * x
    hi = c - (c - x)
    return hi, x - hi


def two_product(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(p, e)`` with ``p = fl(x y)`` and ``x y = p + e`` exactly (no over/underflow assumed)."""
    p = x * y
    xh, xl = _split(x)
    yh, yl = _split(y)
    return p, ((xh * yh - p) + xh * yl + xl * yh) + xl * yl


def sum_side(a: np.ndarray, b: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``sign(a + b - s)`` for ``s = fl(a + b)`` (finite)."""
    bb = s - a
    return _sign((a - (s - bb)) + (b - bb))


def product_side(a: np.ndarray, b: np.ndarray, r: np.ndarray) -> np.ndarray:
    """``sign(a b - r)`` for ``r = fl(a b)`` (finite)."""
    ma, ea = np.frexp(a)
    mb, eb = np.frexp(b)
    p, e = two_product(ma, mb)
    return _sign((p - np.ldexp(r, -(ea + eb))) + e)


def quotient_side(a: np.ndarray, b: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``sign(a / b - q)`` for ``q = fl(a / b)`` (finite, ``b`` nonzero)."""
    ma, ea = np.frexp(a)
    mb, eb = np.frexp(b)
    p, e = two_product(np.ldexp(q, eb - ea), mb)
    return _sign((ma - p) - e) * _sign(mb)


def sqrt_side(a: np.ndarray, r: np.ndarray) -> np.ndarray:
    """``sign(sqrt(a) - r)`` for ``r = fl(sqrt(a))`` (``a`` positive and finite)."""
    ma, ea = np.frexp(a)
    odd = (ea & 1) == 1
    ma = np.where(odd, ma / 2, ma)  # even exponent, significand in [0.25, 1)
    ea = np.where(odd, ea + 1, ea)
    rs = np.ldexp(r, -(ea // 2))
    p, e = two_product(rs, rs)
    return _sign((ma - p) - e)
