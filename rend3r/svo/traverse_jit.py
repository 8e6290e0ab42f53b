"""Compiled (numba) Algorithm 4 in 16.16 fixed point: one ray at a time, per-ray loop.

The same state machine, integer arithmetic, short-stack and restart semantics as the
lockstep numpy traversal in :mod:`rend3r.svo.traverse`, step for step, so every output
(hit, t, entered axis, voxel, counters, memory-request trace) is bit-identical; the tests
check that. Importing this module imports numba: :func:`rend3r.svo.traverse.trace` loads
it only when the numba kernel is selected. The ray setup (normalisation, clamping,
dir-mask, root t-values rounded to 16.16) runs in the kernel too, repeating
:func:`rend3r.svo.traverse.setup_rays` operation for operation.

The kernel is compiled on first use (several seconds). Numba caches the machine code on
disk (``__pycache__`` next to this file, or numba's per-user cache directory when that is
not writable) so later processes load it in a second or two; set
``REND3R_JIT_CACHE=0`` to compile in memory only (the tests do).
"""

from __future__ import annotations

import os

import numpy as np
from numba import njit

from .fixed import INT32_MAX, INT32_MIN, MIN_DIR, ONE

_CACHE = os.environ.get("REND3R_JIT_CACHE", "1") != "0"
#: initial trace capacity per ray (grown by doubling when a frame needs more)
_TRACE_PER_RAY = 16


@njit(cache=_CACHE, nogil=True, inline="always")
def _first_index(t00, t01, t02, t10, t11, t12):
    """FIRSTINDEX(t_enter, t_m): bit a set where the entry lies beyond the middle plane."""
    enter = max(max(t00, t01), t02)
    idx = 0
    if enter > (t00 + t10) >> 1:
        idx |= 4
    if enter > (t01 + t11) >> 1:
        idx |= 2
    if enter > (t02 + t12) >> 1:
        idx |= 1
    return idx


@njit(cache=_CACHE, nogil=True, inline="always")
def _popcount8(x):
    x = x & 0xFF
    x = x - ((x >> 1) & 0x55)
    x = (x & 0x33) + ((x >> 2) & 0x33)
    return (x + (x >> 4)) & 0x0F


@njit(cache=_CACHE, nogil=True)
def _grow(buf, need):
    """A copy of ``buf`` with room for at least ``need`` entries (doubling)."""
    out = np.empty(max(need, 2 * buf.shape[0]), dtype=buf.dtype)
    out[:buf.shape[0]] = buf
    return out


@njit(cache=_CACHE, nogil=True, inline="always")
def _record(rec_ray, rec_addr, rec_lvl, nrec, ray, addr, lvl):
    """Append one memory request (ray, word address, level) to the trace buffers."""
    if nrec + 1 > rec_ray.shape[0]:
        rec_ray = _grow(rec_ray, nrec + 1)
        rec_addr = _grow(rec_addr, nrec + 1)
        rec_lvl = _grow(rec_lvl, nrec + 1)
    rec_ray[nrec] = ray
    rec_addr[nrec] = addr
    rec_lvl[nrec] = lvl
    return rec_ray, rec_addr, rec_lvl, nrec + 1


@njit(cache=_CACHE, nogil=True)
def _to_fixed(x):
    """16.16 rounding of :func:`rend3r.svo.fixed.to_fixed` (round half to even)."""
    v = np.rint(x * ONE)
    if not (INT32_MIN <= v <= INT32_MAX):
        raise OverflowError("value outside the 16.16 range [-32768, 32768)")
    return np.int64(v)


@njit(cache=_CACHE, nogil=True)
def _clamp(x):
    """Direction component clamped to |x| >= 2^-10 (0 counts as positive)."""
    if abs(x) < MIN_DIR:
        return -MIN_DIR if x < 0 else MIN_DIR
    return x


@njit(cache=_CACHE, nogil=True, boundscheck=False, error_model="numpy")
def _kernel(words, origin, direction, root_table, stack_depth, limit, record):
    """Set up and trace every ray; see :func:`trace_fixed`.

    The ray setup repeats :func:`rend3r.svo.traverse.setup_rays` operation for operation
    (the same float64 operations in the same order, hence the same roundings).
    ``record`` is ``None`` for the fast variant or any int to record the request trace:
    numba compiles one machine-code version per argument type and prunes every
    ``record is not None`` branch at compile time, so the fast loop carries no recording
    code or trace buffers.
    """
    n = origin.shape[0]
    S = stack_depth
    one = float(ONE)
    root_word = np.int64(words[0])
    bad = 0
    out_hit = np.zeros(n, dtype=np.bool_)
    out_t = np.full(n, np.inf)
    out_axis = np.full(n, -1, dtype=np.int8)
    out_code = np.full(n, -1, dtype=np.int64)
    out_req = np.zeros(n, dtype=np.int32)
    out_steps = np.zeros(n, dtype=np.int32)
    out_desc = np.zeros(n, dtype=np.int32)
    out_pops = np.zeros(n, dtype=np.int32)
    out_rest = np.zeros(n, dtype=np.int32)
    out_lvl = np.zeros(n, dtype=np.int8)
    out_stack = np.zeros(n, dtype=np.int8)
    cap = 1
    if record is not None:
        cap = n * _TRACE_PER_RAY + 16
    rec_ray = np.empty(cap, dtype=np.int64)
    rec_addr = np.empty(cap, dtype=np.int64)
    rec_lvl = np.empty(cap, dtype=np.int64)
    nrec = 0
    s_word = np.zeros(max(S, 1), dtype=np.int64)
    s_table = np.zeros(max(S, 1), dtype=np.int64)
    s_meta = np.zeros(max(S, 1), dtype=np.int64)

    for r in range(n):
        ox, oy, oz = origin[r, 0], origin[r, 1], origin[r, 2]
        dx, dy, dz = direction[r, 0], direction[r, 1], direction[r, 2]
        sc = np.sqrt((dx * dx + dy * dy) + dz * dz)
        if not (np.isfinite(sc) and sc != 0 and np.isfinite(ox) and np.isfinite(oy)
                and np.isfinite(oz)):
            bad += 1
            continue
        nx, ny, nz = _clamp(dx / sc), _clamp(dy / sc), _clamp(dz / sc)
        dm = (4 if nx < 0 else 0) | (2 if ny < 0 else 0) | (1 if nz < 0 else 0)
        ax, ay, az = abs(nx), abs(ny), abs(nz)
        mx, my, mz = -ox if nx < 0 else ox, -oy if ny < 0 else oy, -oz if nz < 0 else oz
        f00, f01, f02 = (-1.0 - mx) / ax, (-1.0 - my) / ay, (-1.0 - mz) / az
        f10, f11, f12 = (1.0 - mx) / ax, (1.0 - my) / ay, (1.0 - mz) / az
        enter0 = max(max(f00, f01), f02)
        leave0 = min(min(f10, f11), f12)
        if not (enter0 < leave0 and leave0 > 0):
            continue
        sh = max(enter0, 0.0)
        r00, r01, r02 = _to_fixed(f00 - sh), _to_fixed(f01 - sh), _to_fixed(f02 - sh)
        r10, r11, r12 = _to_fixed(f10 - sh), _to_fixed(f11 - sh), _to_fixed(f12 - sh)
        t00, t01, t02, t10, t11, t12 = r00, r01, r02, r10, r11, r12
        tstart = np.int64(0)
        word = root_word
        table = root_table
        level = 0
        code = np.int64(0)
        top = 0
        count = 0
        requests = 1
        steps = 0
        descents = 0
        pops = 0
        restarts = 0
        maxlvl = 0
        maxstack = 0
        idx = _first_index(t00, t01, t02, t10, t11, t12)
        if record is not None:
            rec_ray, rec_addr, rec_lvl, nrec = _record(rec_ray, rec_addr, rec_lvl, nrec, r, 0, 0)
        while True:
            steps += 1
            if steps > limit:
                raise RuntimeError("traversal did not terminate (bug)")
            s0, s1, s2 = t00 + t10, t01 + t11, t02 + t12
            m0, m1, m2 = s0 >> 1, s1 >> 1, s2 >> 1
            if idx & 4:
                c00, c10 = m0, t10
            else:
                c00, c10 = t00, m0
            if idx & 2:
                c01, c11 = m1, t11
            else:
                c01, c11 = t01, m1
            if idx & 1:
                c02, c12 = m2, t12
            else:
                c02, c12 = t02, m2
            texit = min(min(c10, c11), c12)
            cidx = idx ^ dm
            passed = texit <= tstart
            if not passed and (word >> cidx) & 1:
                enter = max(max(c00, c01), c02)
                axis = 0 if c00 == enter else (1 if c01 == enter else 2)
                out_hit[r] = True
                out_t[r] = (max(enter / one, 0.0) + sh) / sc
                out_axis[r] = axis
                out_code[r] = (code << 3) | cidx
                break
            if not passed and (word >> (8 + cidx)) & 1:
                inner = ((word >> 8) & 0xFF) & ~(word & 0xFF)
                caddr = table + _popcount8(inner & ((1 << cidx) - 1))
                cword = np.int64(words[caddr])
                isfar = (cword >> 16) & 1
                slot = caddr + (cword >> 17)
                ctable = caddr + np.int64(words[slot]) if isfar else slot
                lvl = level + 1
                requests += 1 + isfar
                descents += 1
                if record is not None:
                    rec_ray, rec_addr, rec_lvl, nrec = _record(rec_ray, rec_addr, rec_lvl, nrec, r, caddr, lvl)
                    if isfar:
                        rec_ray, rec_addr, rec_lvl, nrec = _record(rec_ray, rec_addr, rec_lvl, nrec, r, slot, lvl)
                if S:
                    top = top + 1 if top + 1 < S else 0
                    s_word[top] = word
                    s_table[top] = table
                    s_meta[top] = idx | (((s0 & 1) << 2 | (s1 & 1) << 1 | (s2 & 1)) << 3)
                    count = min(count + 1, S)
                    maxstack = max(maxstack, count)
                word = cword
                table = ctable
                level = lvl
                code = (code << 3) | cidx
                maxlvl = max(maxlvl, lvl)
                t00, t01, t02, t10, t11, t12 = c00, c01, c02, c10, c11, c12
                idx = _first_index(t00, t01, t02, t10, t11, t12)
                continue
            b = 4 if c10 == texit else (2 if c11 == texit else 1)
            if not idx & b:
                idx |= b
                continue
            tstart = max(tstart, texit)
            if level == 0:
                break
            if count > 0:
                meta = s_meta[top]
                pidx = meta & 7
                tb = (meta >> 3) & 7
                # t_recover = 2 * t_m + t_bit - t_pass on each axis
                if pidx & 4:
                    t00 = 2 * t00 + ((tb >> 2) & 1) - t10
                else:
                    t10 = 2 * t10 + ((tb >> 2) & 1) - t00
                if pidx & 2:
                    t01 = 2 * t01 + ((tb >> 1) & 1) - t11
                else:
                    t11 = 2 * t11 + ((tb >> 1) & 1) - t01
                if pidx & 1:
                    t02 = 2 * t02 + (tb & 1) - t12
                else:
                    t12 = 2 * t12 + (tb & 1) - t02
                word = s_word[top]
                table = s_table[top]
                idx = pidx
                level -= 1
                code >>= 3
                top = top - 1 if top > 0 else S - 1
                count -= 1
                pops += 1
            else:
                t00, t01, t02, t10, t11, t12 = r00, r01, r02, r10, r11, r12
                word = root_word
                table = root_table
                level = 0
                code = 0
                idx = _first_index(t00, t01, t02, t10, t11, t12)
                restarts += 1
                requests += 1
                if record is not None:
                    rec_ray, rec_addr, rec_lvl, nrec = _record(rec_ray, rec_addr, rec_lvl, nrec, r, 0, 0)
        out_req[r] = requests
        out_steps[r] = steps
        out_desc[r] = descents
        out_pops[r] = pops
        out_rest[r] = restarts
        out_lvl[r] = maxlvl
        out_stack[r] = maxstack
    return (bad, out_hit, out_t, out_axis, out_code, out_req, out_steps, out_desc, out_pops,
            out_rest, out_lvl, out_stack, rec_ray[:nrec], rec_addr[:nrec], rec_lvl[:nrec])


def trace_fixed(words: np.ndarray, origin: np.ndarray, direction: np.ndarray, root_table: int,
                stack_depth: int, limit: int, record: bool) -> tuple:
    """Set up and trace rays ``origin + t * direction`` (arrays (n, 3), octree space).

    Returns the number of refused rays (non-finite origin, zero or non-finite direction;
    the caller raises if it is not 0), then per-ray arrays (hit, t, axis, Morton code,
    requests, steps, descents, pops, restarts, max level, max stack) and the
    memory-request trace (ray, address, level) in ray-major, chronological order (empty
    unless ``record``).
    """
    return _kernel(np.ascontiguousarray(words, dtype=np.uint32),
                   np.ascontiguousarray(origin, dtype=np.float64),
                   np.ascontiguousarray(direction, dtype=np.float64),
                   int(root_table), int(stack_depth), int(limit), 1 if record else None)
