"""Ray traversal of the thesis's octree: Algorithm 4 in 16.16 fixed point, and a float64
reference running the same state machine on float values.

The rays of one call run in lockstep with numpy: every iteration each active ray does
one NEXT-EVAL/CALC-CHILD-T/EVAL step (evaluate the current child, then pass it, hit it,
descend into it, or move to the next child and possibly pop or restart).

Errata of the printed algorithms, and what this module does instead:

* t_m is (t0 + t1) / 2 (Algorithm 4 line 15 prints t0 + t0), computed as an arithmetic
  shift that keeps the dropped bit t_bit.
* FIRSTINDEX compares t_enter with t_m (Algorithm 3 line 10 passes t0); bit 2 (X) set
  means the high side of the middle plane, as Algorithm 1 computes.
* Every non-descending step calls NEXTINDEX and assigns the index (Algorithm 3 only does
  so for valid children, and assigns to child-node).
* A hit reports the *child's* entry t (Algorithm 4 line 58 returns the parent's).
* The ray setup rejects rays that miss the root box (Algorithm 4 assumes a hit).
* Leaving a node sets t_start = max(t_start, t_exit_child) on a pop as well as on a
  restart. With that rule a pop and a restart pass exactly the same children, so the
  image does not depend on the stack depth (only the cost does), even for rays through
  edges and corners where zero-length children would otherwise differ.

Ray setup (the software side in the thesis): the direction is normalised to unit
length, each component clamped to |d| >= 2^-10 and mirrored to positive with the 3-bit
dir-mask; the root t-values are computed in float64, shifted so that t = 0 is the
later of the ray start and the root entry (so |t| < 2^12 and nothing can overflow), and
rounded to 16.16. Results are converted back to the caller's t.

The fixed-point traversal also exists as a compiled per-ray kernel
(:mod:`rend3r.svo.traverse_jit`, needs numba: ``pip install 'rend3r[fast]'``), bit-identical
to this one on every output; ``trace(kernel=...)`` chooses.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .fixed import ONE, clamp_direction, to_fixed
from .octree import Octree, child_table, morton_decode, popcount8

Kernel = Literal["auto", "numba", "numpy"]
KERNELS: tuple[str, ...] = ("auto", "numba", "numpy")
#: rays per traversal call: the compiled kernel takes about 10 ms for 2^14 rays, the numpy
#: lockstep needs larger batches to stay efficient (each of its steps is a few dozen numpy
#: calls over the batch), and is interruptible inside a batch anyway
CHUNK_RAYS = {"numba": 1 << 14, "numpy": 1 << 16}
_AXIS_BIT = (4, 2, 1)
#: _SIDE[i, a]: child index i is on the high side of axis a's middle plane
_SIDE = ((np.arange(8)[:, None] >> np.array([2, 1, 0])) & 1).astype(bool)


@dataclass
class TraceResult:
    """Per-ray results of :func:`trace` (arrays of length n)."""

    hit: np.ndarray         #: bool: the ray hit a solid voxel
    t: np.ndarray           #: float64: hit parameter in the caller's t (inf on a miss)
    axis: np.ndarray        #: int8: axis of the entered voxel face (0 x, 1 y, 2 z), -1 miss
    voxel: np.ndarray       #: int64 (n, 3): coordinates of the hit voxel, -1 on a miss
    requests: np.ndarray    #: int32: memory requests (node words and far slots)
    steps: np.ndarray       #: int32: child evaluations (NEXT-EVAL/EVAL iterations)
    descents: np.ndarray    #: int32: pushes / descents into inner children
    pops: np.ndarray        #: int32: stack pops
    restarts: np.ndarray    #: int32: restarts from the root
    max_level: np.ndarray   #: int8: deepest node level entered
    max_stack: np.ndarray   #: int8: most stack entries held
    trace_ray: np.ndarray | None = None    #: ray of each memory request, ray-major order
    trace_addr: np.ndarray | None = None   #: word address of each request
    trace_level: np.ndarray | None = None  #: node level of each request (0 = root)

    def stats(self) -> dict[str, float]:
        """Frame totals: rays, hits, node fetches, restarts, pops, deepest stack use."""
        return {
            "rays": int(len(self.hit)),
            "hits": int(self.hit.sum()),
            "requests": int(self.requests.sum()),
            "steps": int(self.steps.sum()),
            "descents": int(self.descents.sum()),
            "pops": int(self.pops.sum()),
            "restarts": int(self.restarts.sum()),
            "max_stack": int(self.max_stack.max(initial=0)),
            "requests_per_ray": float(self.requests.mean()) if len(self.hit) else 0.0,
        }


def _first_index(t0: list, t1: list, fixed: bool) -> np.ndarray:
    """FIRSTINDEX(t_enter, t_m) of a node with t-values t0, t1."""
    enter = np.maximum(np.maximum(t0[0], t0[1]), t0[2])
    idx = np.zeros(len(enter), dtype=np.int64)
    for a in range(3):
        tm = (t0[a] + t1[a]) >> 1 if fixed else (t0[a] + t1[a]) * 0.5
        idx |= np.where(enter > tm, _AXIS_BIT[a], 0)
    return idx


def _check_rays(o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The rays' |d| (n,); ValueError counting the rays with a non-finite origin or a zero or
    non-finite direction."""
    # |d| summed in a fixed order (the compiled kernel repeats it operation for operation)
    scale = np.sqrt((d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]) + d[:, 2] * d[:, 2])
    bad = ~np.isfinite(scale) | (scale == 0) | ~np.all(np.isfinite(o), axis=1)
    if bad.any():
        raise ValueError(f"{int(bad.sum())} rays have a non-finite origin or a zero/non-finite direction")
    return scale


def setup_rays(origin: np.ndarray, direction: np.ndarray):
    """Ray setup: (hits root, dir-mask, root t0 (3, n), root t1 (3, n), shift, scale).

    t-values are float64 in units of the normalised, clamped direction, shifted so that
    0 is the later of the ray start and the root entry; a caller's t is
    ``(t + shift) / scale``.
    """
    o = np.asarray(origin, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(direction, dtype=np.float64).reshape(-1, 3)
    scale = _check_rays(o, d)
    dn = clamp_direction(d / scale[:, None])
    neg = dn < 0
    dmask = (neg[:, 0] * 4 + neg[:, 1] * 2 + neg[:, 2]).astype(np.int64)
    om = np.where(neg, -o, o)
    dm = np.abs(dn)
    t0 = ((-1.0 - om) / dm).T
    t1 = ((1.0 - om) / dm).T
    enter = t0.max(0)
    leave = t1.min(0)
    hits = (enter < leave) & (leave > 0)
    shift = np.where(hits, np.maximum(enter, 0.0), 0.0)
    return hits, dmask, t0 - shift, t1 - shift, shift, scale


def resolve_kernel(kernel: str, fixed: bool = True) -> tuple[str, str | None]:
    """The traversal ``kernel`` ("auto", "numba", "numpy") runs as: (kernel, note or None).

    "auto" is the compiled numba kernel for fixed point when numba imports, else numpy
    with a note saying so. The float64 reference always runs on numpy. Raises ValueError
    for an unknown name, for "numba" with float64, or for "numba" without numba.
    """
    if kernel not in KERNELS:
        raise ValueError(f"unknown traversal kernel {kernel!r} (choose from {', '.join(KERNELS)})")
    if not fixed:
        if kernel == "numba":
            raise ValueError("the numba kernel runs 16.16 fixed point; the float64 reference runs on numpy")
        return "numpy", None
    if kernel == "numpy":
        return "numpy", None
    try:
        importlib.import_module(".traverse_jit", __package__)  # imports numba
    except ImportError as exc:
        hint = "pip install 'rend3r[fast]' for the compiled kernel"
        if kernel == "numba":
            raise ValueError(f"numba kernel unavailable ({exc}); {hint}") from None
        return "numpy", f"numba is not available ({exc}): using the numpy traversal (about 10x slower); {hint}"
    return "numba", None


def trace(tree: Octree, origin: np.ndarray, direction: np.ndarray, stack_depth: int = 8,
          fixed: bool = True, record: bool = False, kernel: Kernel = "auto",
          on_rays: Callable[[int], None] | None = None) -> TraceResult:
    """Trace rays ``origin + t * direction`` (octree space, root = [-1, 1]^3).

    ``stack_depth`` is the short stack's depth (0 = restart only); when full, a push
    drops the oldest entry. ``fixed`` selects 16.16 arithmetic (else float64). With
    ``record`` the memory requests are returned in ray-major order for cache models.
    ``kernel`` selects the implementation (see :func:`resolve_kernel`; results are
    identical). The rays are traced in chunks (:data:`CHUNK_RAYS`), so a Ctrl-C is seen
    between chunks; ``on_rays(count)`` is called after each with the rays it traced.
    """
    if stack_depth < 0:
        raise ValueError("stack depth must be >= 0")
    use, _ = resolve_kernel(kernel, fixed)
    o = np.asarray(origin, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(direction, dtype=np.float64).reshape(-1, 3)
    if len(o) != len(d):
        o, d = np.broadcast_arrays(o, d)
    _check_rays(o, d)
    # a step cap far above any correct traversal; reaching it means a bug, not a hard ray
    limit = 64 * 8 * (tree.depth + 1) * (1 << min(tree.depth, 12))
    root_table = int(child_table(tree.words, np.zeros(1, dtype=np.int64))[0][0])
    if use == "numba":
        from .interrupt import off_main_thread

        def one(lo: int, hi: int) -> TraceResult:
            return off_main_thread(_trace_numba, tree, o[lo:hi], d[lo:hi], root_table,
                                   stack_depth, limit, record)
    else:
        def one(lo: int, hi: int) -> TraceResult:
            return _trace_numpy(tree, o[lo:hi], d[lo:hi], root_table, stack_depth, fixed,
                                limit, record)
    step = CHUNK_RAYS[use]
    parts = []
    for lo in range(0, max(len(o), 1), step):  # no rays: one empty chunk
        parts.append(one(lo, min(lo + step, len(o))))
        if on_rays is not None:
            on_rays(len(parts[-1].hit))
    return _concatenate(parts, record) if len(parts) != 1 else parts[0]


def _concatenate(parts: list[TraceResult], record: bool) -> TraceResult:
    """One :class:`TraceResult` from the results of consecutive chunks of rays."""
    fields = ("hit", "t", "axis", "voxel", "requests", "steps", "descents", "pops", "restarts",
              "max_level", "max_stack")
    result = TraceResult(*(np.concatenate([getattr(p, f) for p in parts]) for f in fields))
    if record:
        first = np.cumsum([0] + [len(p.hit) for p in parts[:-1]])
        result.trace_ray = np.concatenate([p.trace_ray + off for p, off in zip(parts, first)])
        result.trace_addr = np.concatenate([p.trace_addr for p in parts])
        result.trace_level = np.concatenate([p.trace_level for p in parts])
    return result


def _trace_numpy(tree: Octree, origin: np.ndarray, direction: np.ndarray, root_table: int,
                 stack_depth: int, fixed: bool, limit: int, record: bool) -> TraceResult:
    """:func:`trace` on the lockstep numpy traversal, ray setup included."""
    hits_root, dmask, rt0, rt1, shift, scale = setup_rays(origin, direction)
    n = len(hits_root)
    out = {name: np.zeros(n, dtype=np.int32) for name in
           ("requests", "steps", "descents", "pops", "restarts")}
    out_lvl = np.zeros(n, dtype=np.int8)
    out_stack = np.zeros(n, dtype=np.int8)
    out_hit = np.zeros(n, dtype=bool)
    out_t = np.full(n, np.inf)
    out_axis = np.full(n, -1, dtype=np.int8)
    out_code = np.full(n, -1, dtype=np.int64)
    rec_ray, rec_addr, rec_lvl = [], [], []

    rid = np.flatnonzero(hits_root)
    m = len(rid)
    if fixed:
        rt0q, rt1q = to_fixed(rt0[:, rid]), to_fixed(rt1[:, rid])
    else:
        rt0q, rt1q = rt0[:, rid].copy(), rt1[:, rid].copy()
    S = stack_depth
    words = tree.words.astype(np.int64)
    root_word = int(words[0])
    zero_t = 0 if fixed else 0.0
    st = {
        "rid": rid, "dmask": dmask[rid],
        "rt0": rt0q.T.copy(), "rt1": rt1q.T.copy(),
        "t0": rt0q.T.copy(), "t1": rt1q.T.copy(),
        "tstart": np.full(m, zero_t, dtype=rt0q.dtype),
        "word": np.full(m, root_word, dtype=np.int64),
        "table": np.full(m, root_table, dtype=np.int64),
        "level": np.zeros(m, dtype=np.int64),
        "code": np.zeros(m, dtype=np.int64),
        "top": np.zeros(m, dtype=np.int64), "count": np.zeros(m, dtype=np.int64),
        "requests": np.ones(m, dtype=np.int32), "steps": np.zeros(m, dtype=np.int32),
        "descents": np.zeros(m, dtype=np.int32), "pops": np.zeros(m, dtype=np.int32),
        "restarts": np.zeros(m, dtype=np.int32), "maxlvl": np.zeros(m, dtype=np.int8),
        "maxstack": np.zeros(m, dtype=np.int8),
    }
    if S:
        st["s_word"] = np.zeros((m, S), dtype=np.int64)
        st["s_table"] = np.zeros((m, S), dtype=np.int64)
        st["s_meta"] = np.zeros((m, S), dtype=np.int64)
        if not fixed:
            st["s_t0"] = np.zeros((m, S, 3))
            st["s_t1"] = np.zeros((m, S, 3))
    st["idx"] = _first_index(list(st["t0"].T), list(st["t1"].T), fixed)
    if record:
        rec_ray.append(rid.copy())
        rec_addr.append(np.zeros(m, dtype=np.int64))
        rec_lvl.append(np.zeros(m, dtype=np.int64))

    def finish(sel: np.ndarray) -> None:
        r = st["rid"][sel]
        for name in out:
            out[name][r] = st[name][sel]
        out_lvl[r] = st["maxlvl"][sel]
        out_stack[r] = st["maxstack"][sel]

    iteration = 0
    alive = np.ones(m, dtype=bool)
    n_alive = m
    while n_alive:
        iteration += 1
        if iteration > limit:
            raise RuntimeError("traversal did not terminate (bug)")
        t0, t1, idx, word = st["t0"], st["t1"], st["idx"], st["word"]
        st["steps"] += alive
        tsum = t0 + t1
        tm = tsum >> 1 if fixed else tsum * 0.5
        bits = _SIDE[idx]
        t0c = np.where(bits, tm, t0)
        t1c = np.where(bits, t1, tm)
        texit = np.minimum(np.minimum(t1c[:, 0], t1c[:, 1]), t1c[:, 2])
        cidx = idx ^ st["dmask"]
        valid = (word >> (8 + cidx)) & 1
        leaf = (word >> cidx) & 1
        passed = texit <= st["tstart"]
        hit = ~passed & (leaf == 1) & alive
        desc = ~passed & (leaf == 0) & (valid == 1) & alive
        nxt = ~(hit | desc) & alive
        done = hit.copy()

        if hit.any():
            h = np.flatnonzero(hit)
            tc = t0c[h]
            enter = np.maximum(np.maximum(tc[:, 0], tc[:, 1]), tc[:, 2])
            axis = np.where(tc[:, 0] == enter, 0, np.where(tc[:, 1] == enter, 1, 2))
            r = st["rid"][h]
            tf = enter / ONE if fixed else enter
            out_hit[r] = True
            out_t[r] = (np.maximum(tf, 0.0) + shift[r]) / scale[r]
            out_axis[r] = axis
            out_code[r] = (st["code"][h] << 3) | cidx[h]

        if desc.any():
            D = np.flatnonzero(desc)
            w = word[D]
            ci = cidx[D]
            inner = ((w >> 8) & 0xFF) & ~(w & 0xFF)
            caddr = st["table"][D] + popcount8(inner & ((1 << ci) - 1))
            cword = words[caddr]
            isfar = ((cword >> 16) & 1) == 1
            ptr = cword >> 17
            slot = caddr + ptr
            ctable = np.where(isfar, caddr + words[np.where(isfar, slot, 0)], slot)
            lvl = st["level"][D] + 1
            st["requests"][D] += 1 + isfar
            st["descents"][D] += 1
            if record:
                rec_ray.append(st["rid"][D])
                rec_addr.append(caddr)
                rec_lvl.append(lvl)
                if isfar.any():
                    rec_ray.append(st["rid"][D[isfar]])
                    rec_addr.append(slot[isfar])
                    rec_lvl.append(lvl[isfar])
            if S:
                top = (st["top"][D] + 1) % S
                st["top"][D] = top
                st["s_word"][D, top] = w
                st["s_table"][D, top] = st["table"][D]
                meta = idx[D]
                if fixed:
                    tb = tsum[D] & 1
                    meta = meta | ((tb[:, 0] << 2 | tb[:, 1] << 1 | tb[:, 2]) << 3)
                else:
                    st["s_t0"][D, top] = t0[D]
                    st["s_t1"][D, top] = t1[D]
                st["s_meta"][D, top] = meta
                cnt = np.minimum(st["count"][D] + 1, S)
                st["count"][D] = cnt
                st["maxstack"][D] = np.maximum(st["maxstack"][D], cnt)
            st["word"][D] = cword
            st["table"][D] = ctable
            st["level"][D] = lvl
            st["code"][D] = (st["code"][D] << 3) | ci
            st["maxlvl"][D] = np.maximum(st["maxlvl"][D], lvl)
            nt0, nt1 = t0c[D], t1c[D]
            t0[D] = nt0
            t1[D] = nt1
            idx[D] = _first_index(list(nt0.T), list(nt1.T), fixed)

        if nxt.any():
            N = np.flatnonzero(nxt)
            tc1 = t1c[N]
            te = texit[N]
            b = np.where(tc1[:, 0] == te, 4, np.where(tc1[:, 1] == te, 2, 1))
            exits = (idx[N] & b) != 0
            stay = N[~exits]
            idx[stay] |= b[~exits]
            E = N[exits]
            if len(E):
                st["tstart"][E] = np.maximum(st["tstart"][E], texit[E])
                lvl = st["level"][E]
                miss = E[lvl == 0]
                done[miss] = True
                up = E[lvl > 0]
                if S:
                    pop = up[st["count"][up] > 0]
                    restart = up[st["count"][up] == 0]
                else:
                    pop = up[:0]
                    restart = up
                if len(pop):
                    top = st["top"][pop]
                    meta = st["s_meta"][pop, top]
                    pidx = meta & 7
                    if fixed:
                        cb = _SIDE[pidx]
                        tbit = _SIDE[(meta >> 3) & 7].astype(t0.dtype)
                        c0, c1 = t0[pop], t1[pop]
                        tmv = np.where(cb, c0, c1)
                        tpass = np.where(cb, c1, c0)
                        trec = 2 * tmv + tbit - tpass
                        t0[pop] = np.where(cb, trec, tpass)
                        t1[pop] = np.where(cb, tpass, trec)
                    else:
                        t0[pop] = st["s_t0"][pop, top]
                        t1[pop] = st["s_t1"][pop, top]
                    word[pop] = st["s_word"][pop, top]
                    st["table"][pop] = st["s_table"][pop, top]
                    idx[pop] = pidx
                    st["level"][pop] -= 1
                    st["code"][pop] >>= 3
                    st["top"][pop] = (top - 1) % S
                    st["count"][pop] -= 1
                    st["pops"][pop] += 1
                if len(restart):
                    t0[restart] = st["rt0"][restart]
                    t1[restart] = st["rt1"][restart]
                    word[restart] = root_word
                    st["table"][restart] = root_table
                    st["level"][restart] = 0
                    st["code"][restart] = 0
                    idx[restart] = _first_index(list(t0[restart].T), list(t1[restart].T), fixed)
                    st["restarts"][restart] += 1
                    st["requests"][restart] += 1
                    if record:
                        rec_ray.append(st["rid"][restart])
                        rec_addr.append(np.zeros(len(restart), dtype=np.int64))
                        rec_lvl.append(np.zeros(len(restart), dtype=np.int64))

        if done.any():
            finish(done)
            alive &= ~done
            n_alive = int(alive.sum())
            # compact only when many rays have finished: copying every state array each
            # iteration would cost more than carrying finished rays for a while
            if n_alive < 0.7 * len(alive):
                st = {k: v[alive] for k, v in st.items()}
                alive = np.ones(n_alive, dtype=bool)

    voxel = np.full((n, 3), -1, dtype=np.int64)
    voxel[out_hit] = morton_decode(out_code[out_hit], tree.depth)
    result = TraceResult(out_hit, out_t, out_axis, voxel, out["requests"], out["steps"],
                         out["descents"], out["pops"], out["restarts"], out_lvl, out_stack)
    if record:
        ray = np.concatenate(rec_ray) if rec_ray else np.zeros(0, np.int64)
        order = np.argsort(ray, kind="stable")
        result.trace_ray = ray[order]
        result.trace_addr = np.concatenate(rec_addr)[order] if rec_addr else ray
        result.trace_level = np.concatenate(rec_lvl)[order] if rec_lvl else ray
    return result


def _trace_numba(tree: Octree, origin: np.ndarray, direction: np.ndarray, root_table: int,
                 stack_depth: int, limit: int, record: bool) -> TraceResult:
    """:func:`trace` on the compiled kernel (fixed point), ray setup included."""
    from .traverse_jit import trace_fixed

    (bad, hit, t, axis, code, requests, steps, descents, pops, restarts, max_level, max_stack,
     rec_ray, rec_addr, rec_lvl) = trace_fixed(tree.words, origin, direction, root_table, stack_depth, limit, record)
    if bad:
        raise ValueError(f"{bad} rays have a non-finite origin or a zero/non-finite direction")
    n = len(hit)
    voxel = np.full((n, 3), -1, dtype=np.int64)
    voxel[hit] = morton_decode(code[hit], tree.depth)
    result = TraceResult(hit, t, axis, voxel, requests, steps, descents, pops, restarts,
                         max_level, max_stack)
    if record:
        result.trace_ray, result.trace_addr, result.trace_level = rec_ray, rec_addr, rec_lvl
    return result
