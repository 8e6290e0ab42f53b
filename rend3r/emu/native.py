"""The compiled kernels (``rend3r/emu/csrc``), loaded with ctypes.

The C extension ``rend3r.emu._kernels`` is built when rend3r is installed (``setup.py``),
so nothing is compiled at run time. Calls through ctypes release the GIL: threads run
kernels on every core. Argument blocks mirror ``csrc/kernels.h``; :func:`ptr` gives an
array's address after checking its dtype and layout, so a kernel never sees an array of
another type or shape than it was written for.
"""

from __future__ import annotations

import ctypes
import importlib.util
import os
from ctypes import POINTER, Structure, c_double, c_int32, c_int64, c_uint64, c_void_p, cast, pointer
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from ..errors import Rend3rError
from ..precision.formats import FloatFormat, parse
from ..precision.stages import STAGES

if TYPE_CHECKING:
    from .arith import Arith

# Column layouts shared with csrc/kernels.h.
SF_LOC, SF_ROT, SF_INV, SF_ZSIGN, SF_ONE, SF_SHAT, SF_C2, SF_COLUMNS = 0, 3, 7, 10, 11, 12, 15, 16
SI_IDENT, SI_COLOUR, SI_COLUMNS = 0, 1, 2
B_CENTER, B_SMIN, B_SMAX, B_COLUMNS = 0, 3, 4, 5
CAM_ORIGIN, CAM_TMIN, CAM_TMAX, CAM_Z, CAM_ROT, CAM_COLUMNS = 0, 3, 4, 5, 6, 10
LT_KIND, LT_LOC, LT_DIR, LT_INTENSITY, LT_COLUMNS = 0, 1, 4, 7, 8
LIGHT_DIRECTIONAL, LIGHT_POINT = 1, 2
TRACE_SHAPE_VALUES, TRACE_LIGHT_VALUES = 22, 12
OUT_TESTS, OUT_NAN_TESTS, OUT_SHADOW_RAYS, OUT_HITS, OUT_LO, OUT_HI = 0, 1, 2, 3, 4, 7
OUT_SHOWN, OUT_NAN_RAYS, OUT_COLUMNS = 10, 11, 12
PC_COLUMNS, P32_COLUMNS = 7, 8  # primary cull data per shape, double and what float lanes read (float)
BVH_CONE, BVH_FLAT = 0, 1  # a hierarchy's bounds around lines through one apex, or parallel lines
BUILD_BYTES, BUILD_ITEM_BYTES = 48, 16  # bvh_build's working room a shape, and a shape's centre and slot
BV_SINE, BV_SIN2, BV_FLOOR, BV_F32, BV_COLUMNS = 3, 5, 6, 7, 10  # their columns; floats from BV_F32 on (csrc/kernels.h)
BX_COLUMNS = 6  # a shape's own box on the axes normal to parallel lines, then rounded to floats (4 floats)
CI_COLUMNS = 5  # a shape's own cone around an apex: unit axis, sine and cosine of its half-angle
SK_COLUMNS, PK_COLUMNS = 6, 9  # a point light's behind terms per shape and per node (csrc/kernels.h)
LAZY_READY, LAZY_WAITING = 0, 1  # a node of a frame's primary bundle: made, or a subtree's root that waits


class Format(Structure):
    """A working format of the _fmt kernels (csrc/fformat.h)."""

    _fields_ = [("drop", c_int64), ("max_bits", c_uint64), ("min_normal_bits", c_uint64),
                ("subnormal_magic", c_double), ("ftz", c_int32), ("wide", c_int32), ("before", c_int32),
                ("stages", c_int32)]

    @classmethod
    def of(cls, ar: Arith):
        """The kernels' format argument: one Format, or for a per-stage map the load format
        (exact float16) and one per stage, in STAGES order (csrc/fformat.h)."""
        if not ar.stages:
            return pointer(cls._one(ar.format, ar.tininess))
        formats = [parse("e5m10", "ieee"), *(ar.stage_formats.get(s, ar.format) for s in STAGES)]
        table = (cls * len(formats))(*(cls._one(f, ar.tininess) for f in formats))
        table[0].stages = len(STAGES)
        return cast(table, POINTER(cls))  # the pointer keeps the table alive

    @classmethod
    def _one(cls, fmt: FloatFormat, tininess: str) -> Format:
        bits = lambda x: int(np.float64(x).view(np.uint64))  # noqa: E731
        return cls(52 - fmt.frac_bits, bits(fmt.max), bits(fmt.min_normal),
                   float(np.ldexp(1.0, fmt.emin - fmt.frac_bits + 52)), int(fmt.ftz),
                   int(fmt.frac_bits > 25 or fmt.exp_bits == 11), int(tininess == "before"), 0)


class Shapes(Structure):
    _fields_ = [("sf", c_void_p), ("si", c_void_p), ("bnd", c_void_p), ("n", c_int64), ("u", c_double),
                ("tiny", c_double), ("format", POINTER(Format))]


class Bvh(Structure):
    _fields_ = [("node", c_void_p), ("items", c_void_p), ("box", c_void_p), ("frame", c_double * 6),
                ("nodes", c_int64), ("always", c_void_p), ("nalways", c_int64), ("item_box", c_void_p),
                ("where", c_void_p)]


class Band(Structure):
    _fields_ = [("sh", POINTER(Shapes)), ("cam", c_void_p), ("xs", c_void_p), ("ys", c_void_p),
                ("rotated", c_int32), ("lit", c_int32), ("width", c_int64), ("row0", c_int64), ("row_magic", c_uint64),
                ("dirs", c_void_p), ("pc", c_void_p), ("pc32", c_void_p), ("floor", c_void_p), ("tree", Bvh),
                ("slot", c_void_p), ("sqd", c_void_p),
                ("pt", c_void_p), ("nm", c_void_p), ("npix", c_int64), ("bad", c_void_p), ("nan_px", c_void_p),
                ("acc", c_void_p), ("index", c_void_p), ("background", c_int32), ("rgb", c_void_p),
                ("depth", c_void_p), ("prov", c_void_p), ("in_pass", c_void_p), ("lazy", c_void_p)]


class Pairs(Structure):
    """SE/SD pairs for pairs_rows and pairs_grow (csrc/kernels.c Pairs)."""

    _fields_ = [("words", c_void_p), ("n_words", c_int64), ("at", c_void_p), ("n", c_int64), ("fields", c_void_p),
                ("tables", c_void_p), ("entry", c_int32), ("wanted", c_void_p), ("null", c_void_p),
                ("records", c_void_p), ("avx2", c_int32)]


class LightPass(Structure):
    _fields_ = [("sh", POINTER(Shapes)), ("band", POINTER(Band)), ("light", c_void_p), ("scale", c_double * 3),
                ("fixed", c_int32), ("shadows", c_int32), ("parallel", c_int32),
                ("first", c_int32), ("last", c_int32), ("behind", c_void_p),
                ("l_hat", c_double * 3), ("l_len", c_double), ("radius", c_void_p), ("tree", Bvh), ("keys", c_void_p),
                ("point_keys", c_void_p), ("serial", c_int64)]


class TreeMemo(Structure):
    """What a thread's tree builds keep (csrc/kernels.h TreeMemo, bvh.py tree_room)."""

    _fields_ = [("capacity", c_int64), ("valid", c_int64), ("rows", c_int64), ("counts", c_int64 * 2),
                ("nodes", c_int64), ("kept", c_int64), ("last", c_int64), ("given", c_void_p), ("items", c_void_p),
                ("always", c_void_p), ("where", c_void_p), ("node", c_void_p)]


class Setup(Structure):
    """A frame's set-up (csrc/kernels.h Setup, csrc/setup.c frame_setup)."""

    _fields_ = [("tables", c_void_p), ("values", c_void_p), ("index", c_void_p), ("rows", c_int64), ("props", c_void_p),
                ("kinds", c_void_p), ("cam", c_void_p), ("tiny", c_double), ("format", POINTER(Format)),
                ("sf", c_void_p), ("sf_row", c_int64), ("si", c_void_p), ("bnd", c_void_p), ("bounded", c_void_p),
                ("index_out", c_void_p), ("items", c_void_p), ("always", c_void_p), ("node", c_void_p),
                ("where", c_void_p),
                ("room", c_void_p), ("memo", c_void_p), ("counts", c_int64 * 2), ("nodes", c_int64),
                ("shapes", c_int64), ("jobs", c_int32), ("isa", c_int32), ("chunk", c_int64)]


PASS_NONE, PASS_PRIMARY, PASS_SHADOW = 0, 1, 2  # a Bundle's shape pass (csrc/kernels.h)


class Bundle(Structure):
    """One bundle of rays' bounds (csrc/kernels.h Bundle, csrc/setup.c bundle_bounds)."""

    _fields_ = [("bnd", c_void_p), ("ok", c_void_p), ("n", c_int64), ("pass_", c_int32), ("kind", c_int32),
                ("apex", c_double * 3), ("dmin", c_double), ("dmax", c_double), ("mid", c_double * 3),
                ("half", c_double), ("magnitude", c_double), ("chord", c_double), ("l_len", c_double),
                ("unit", c_void_p), ("u", c_double), ("tiny", c_double), ("overflow", c_double),
                ("radius", c_void_p), ("floor", c_void_p), ("pc", c_void_p), ("pc32", c_void_p), ("behind", c_void_p),
                ("keys", c_void_p), ("point", c_void_p), ("tree", Bvh), ("items", c_int64), ("box", c_void_p),
                ("own", c_void_p), ("node_keys", c_void_p), ("jobs", c_int32), ("isa", c_int32), ("chunk", c_int64),
                ("lazy", c_void_p), ("lazy_items", c_int64)]


LF_PARALLEL, LF_APEX, LF_UNIT, LF_LENGTH, LF_AXES, LF_COLUMNS = 0, 1, 4, 7, 8, 14
BC_COLUMNS = 6  # render_band's counts (csrc/kernels.h BC_*)


class Bands(Structure):
    """A frame's bands, each rendered in one call (csrc/kernels.h Bands, csrc/band.c render_band)."""

    _fields_ = [("band", POINTER(Band)), ("directions", c_void_p), ("nearest", c_void_p), ("light_pass", c_void_p),
                ("shadow_origins", c_void_p), ("primary", POINTER(Bundle)), ("light_rows", c_void_p),
                ("light_row", c_int64), ("lights", c_int64), ("light_frames", c_void_p), ("scales", c_void_p),
                ("fixed", c_int32), ("item", c_int32), ("bounded", c_void_p), ("items", c_int64),
                ("overflow", c_double), ("jobs", c_int32), ("isa", c_int32), ("chunk", c_int64),
                ("min_chunk", c_int64), ("chunks_per_job", c_int64), ("counts", c_int64 * BC_COLUMNS),
                ("memory", c_void_p), ("memory_bytes", c_int64)]


#: Pixels a band may hold and the widest frame, for Band.row_magic (csrc/kernels.h band_row).
BAND_LIMIT, WIDTH_LIMIT = 1 << 20, 8192


def row_magic(width: int) -> int:
    """Band.row_magic for a frame ``width`` pixels wide."""
    if not 1 <= width <= WIDTH_LIMIT:
        raise ValueError(f"frame width {width} is outside 1..{WIDTH_LIMIT}")
    return (1 << 40) // width + 1


try:  # the address of a C-contiguous array's data: ndarray.ctypes.data in a tenth of the time
    from ._kernels import address
except ImportError:  # no compiled kernels: library() says so when one is first called
    def address(a: np.ndarray) -> int:
        return a.ctypes.data


def ptr(a: np.ndarray, dtype: type | np.dtype, shape: tuple[int | None, ...]) -> int:
    """The address of ``a`` after checking its dtype, C-contiguity and shape (None: any)."""
    if a.dtype == dtype and a.flags.c_contiguous and (a.shape == shape or _fits(a.shape, shape)):
        return address(a)  # (this runs ~15 times a frame: the common case is one comparison each)
    raise TypeError(f"kernel argument: expected {np.dtype(dtype)} {shape}, got {a.dtype} {a.shape}")


def _fits(have: tuple[int, ...], shape: tuple[int | None, ...]) -> bool:
    """Whether an array's shape ``have`` is ``shape``, None matching any length."""
    if len(have) != len(shape):
        return False
    for n, want in zip(have, shape):  # a loop: all(generator) takes twice as long
        if want is not None and n != want:
            return False
    return True


#: The kernels' builds, each instruction set also running the ones before it: portable, AVX2
#: (with F16C), AVX-512 (F, VL, BW and DQ, on the AVX2 build's 256-bit vectors).
INSTRUCTION_SETS = ("base", "avx2", "avx512")
#: Kernel suffix per (precision, flush subnormals); narrow formats' kernels are NARROW's (float
#: lanes, csrc/fnarrow.h), every other format's FORMAT's (double lanes, csrc/fformat.h).
SUFFIXES = {("fp16", True): "h16", ("fp16", False): "h16i", ("fp32", True): "f32", ("fp32", False): "f32",
            ("fp64", True): "f64", ("fp64", False): "f64"}
NARROW, FORMAT = "nar", "fmt"
_SUFFIXED = {  # name: (restype, argtypes); each exists once per suffix and instruction set
    "directions": (None, [POINTER(Band), c_int64, c_int64, c_void_p]),
    "nearest": (None, [POINTER(Band), c_int64, c_int64, c_void_p]),
    "shape_tables": (c_int64, [c_void_p, c_void_p, c_int64, c_void_p, c_void_p, c_void_p, c_double, c_void_p, c_void_p,
                               c_void_p, c_void_p, c_void_p, POINTER(Format), c_int32]),
    "light_pass": (None, [POINTER(LightPass), c_int64, c_int64, c_void_p]),
    "shadow_origins": (None, [POINTER(LightPass), c_int64, c_int64, c_void_p]),
    "trace_pixel": (c_int64, [POINTER(Band), c_int32, c_int32, c_void_p, c_void_p, c_int64, c_int64, c_int64,
                              c_void_p, c_void_p, c_void_p]),
}
_PLAIN = {
    "bvh_build": (c_int64, [c_void_p, c_void_p, c_int64, c_void_p, c_void_p, c_void_p, c_void_p, c_void_p, c_void_p,
                            c_int32, c_void_p, c_int32]),
    "have_avx2": (c_int32, []),
    "have_avx512": (c_int32, []),
    "round16_array": (None, [c_void_p, c_void_p, c_int64, c_int32]),
    "stream_scan": (None, [c_void_p, c_int64, c_int64, c_int32, c_int32, c_int32, c_void_p, c_void_p, c_int64,
                           c_void_p, c_int32]),
    "word_writes": (c_int64, [c_void_p, c_void_p, c_int64, c_void_p, c_void_p, c_void_p, c_void_p, c_void_p, c_void_p]),
    "pairs_rows": (c_int64, [c_void_p, POINTER(Pairs), c_int64, c_void_p, c_void_p, c_void_p, c_void_p, c_void_p,
                             c_int64, c_void_p]),
    "pairs_grow": (None, [c_void_p, POINTER(Pairs), c_int64, c_void_p, c_void_p, c_void_p, c_void_p, c_int64, c_void_p,
                          c_int64, c_void_p, c_void_p, c_void_p]),
    "team_open": (c_void_p, [c_int32]),
    "team_close": (None, [c_void_p]),
    "team_check_runs": (None, [c_void_p, c_void_p, c_int64, c_void_p]),  # tests only (team.c)
    "team_open_backwards": (c_void_p, []),  # tests only (team.c)
    "team_parts": (c_int64, [c_int64, c_int32, c_int64, c_int64]),  # threads.parts
    "frame_setup": (c_int64, [POINTER(Setup), POINTER(Bundle), c_void_p]),
    "bundle_bounds": (None, [POINTER(Bundle), c_void_p]),
    "band_bytes": (c_int64, [POINTER(Bands), c_int64]),
    "render_band": (c_int64, [POINTER(Bands), c_int64, c_int64, c_void_p, c_void_p, c_void_p, c_void_p]),
}
@lru_cache(maxsize=1)
def library() -> ctypes.CDLL:
    """The kernels' shared library, with every function's argument types declared."""
    spec = importlib.util.find_spec("rend3r.emu._kernels")
    if spec is None or spec.origin is None:
        raise Rend3rError("rend3r's compiled kernels are missing: reinstall it (python -m pip install -e .), "
                          "which needs a C compiler")
    lib = ctypes.CDLL(spec.origin)
    table = dict(_PLAIN)
    for name, sig in _SUFFIXED.items():
        for suffix in {*SUFFIXES.values(), NARROW, FORMAT}:
            for isa in INSTRUCTION_SETS:
                table[f"{name}_{suffix}_{isa}"] = sig
    for isa in INSTRUCTION_SETS:
        table[f"round_array_{NARROW}_{isa}"] = (None, [c_void_p, c_void_p, c_int64, POINTER(Format)])
    for name, (restype, argtypes) in table.items():
        fn = getattr(lib, name, None)
        if fn is not None:  # the AVX2 and AVX-512 builds exist on x86-64 only
            fn.restype, fn.argtypes = restype, argtypes
    return lib


def isa() -> str:
    """The instruction set the kernels run in, of INSTRUCTION_SETS: the one :func:`choose`
    set, else the last one the processor runs, up to ``REND3R_ISA`` if set (the same values
    in every one)."""
    return _chosen or _best()


_chosen: str | None = None


def choose(instruction_set: str | None) -> None:
    """Run the kernels of ``instruction_set`` from now on, in every thread, whatever
    ``REND3R_ISA`` says (None: the one :func:`isa` picks by itself); for benchmarks and
    tests that compare the builds. ValueError when it is not one of INSTRUCTION_SETS or
    this build or processor does not run it."""
    global _chosen
    if instruction_set is not None and instruction_set not in INSTRUCTION_SETS:
        raise ValueError(f"no {instruction_set!r} build of the kernels: choose one of {', '.join(INSTRUCTION_SETS)}")
    if instruction_set is not None and not runs(instruction_set):
        raise ValueError(f"this processor does not run the {instruction_set} build of the kernels")
    _chosen = instruction_set


@lru_cache(maxsize=1)
def _best() -> str:
    wanted = os.environ.get("REND3R_ISA") or INSTRUCTION_SETS[-1]
    if wanted not in INSTRUCTION_SETS:
        shown = repr(wanted) if len(wanted) <= 40 else f"{wanted[:40]!r}... ({len(wanted):,} characters)"
        raise Rend3rError(f"REND3R_ISA={shown}: choose one of {', '.join(INSTRUCTION_SETS)}")
    return next(s for s in reversed(INSTRUCTION_SETS[:INSTRUCTION_SETS.index(wanted) + 1]) if runs(s))


def runs(instruction_set: str) -> bool:
    """Whether this build and processor run the kernels of ``instruction_set``."""
    lib = library()
    return instruction_set == "base" or (hasattr(lib, f"nearest_f32_{instruction_set}")
                                         and bool(getattr(lib, f"have_{instruction_set}")()))


def avx2() -> bool:
    """Whether the program's scan and the pairs' decoding (csrc/kernels.c stream_scan,
    pair_marks), which have an AVX2 copy and no other, take it: under either vector build."""
    return isa() != "base"


def shape_isa() -> int:
    """Which copy of the shape passes (csrc/shape_bounds.inc) a Bundle or Bands block asks
    for: 0 portable, 1 AVX2 (four lanes), 2 AVX-512 (eight lanes), the kernels' build's."""
    return INSTRUCTION_SETS.index(isa())


def narrow_format(f: FloatFormat) -> bool:
    """Whether the narrow kernels (float lanes, csrc/fnarrow.h) compute in ``f`` exactly:
    at most 10 fraction bits and at most 7 exponent bits, or 8 with subnormals flushed."""
    return f.frac_bits <= 10 and (f.exp_bits <= 7 or (f.exp_bits == 8 and f.ftz))


def narrow(ar: Arith) -> bool:
    """Whether ``ar`` runs on the narrow kernels: one narrow format (fp16 has kernels of its
    own unless it judges tininess before rounding)."""
    return not ar.native and not ar.stages and narrow_format(ar.format)


def suffix(ar: Arith) -> str:
    """The suffix of the kernels that compute in ``ar``'s working precision."""
    if ar.native:
        return SUFFIXES[ar.precision, ar.ftz]
    return NARROW if narrow(ar) else FORMAT


def dtype(ar: Arith) -> np.dtype:
    """The element type of the kernels' working arrays for ``ar``: float32 for fp16, fp32
    and narrow formats (whose values float32 holds exactly), else float64."""
    return np.dtype(np.float32 if suffix(ar) in ("h16", "h16i", "f32", NARROW) else np.float64)


def kernel(name: str, ar: Arith) -> ctypes._CFuncPtr:
    """The kernel ``name`` compiled for a working precision and subnormal handling (the
    narrow and format kernels are given the format)."""
    return getattr(library(), f"{name}_{suffix(ar)}_{isa()}")


def kernel_address(name: str, ar: Arith) -> int:
    """The address of :func:`kernel` (for the blocks that call one, e.g. Setup.tables)."""
    return _address(f"{name}_{suffix(ar)}_{isa()}")


@lru_cache(maxsize=None)
def _address(symbol: str) -> int:
    return cast(getattr(library(), symbol), c_void_p).value


def round_narrow(values: np.ndarray, ar: Arith, instruction_set: str | None = None) -> np.ndarray:
    """float32 values rounded to ``ar``'s narrow format by the narrow kernels' rounding (for
    tests; ``instruction_set``: one of INSTRUCTION_SETS, default the one in use)."""
    if ar.stages or not narrow_format(ar.format):
        raise ValueError(f"{ar.label} is not a narrow format")
    a = np.ascontiguousarray(values, np.float32)
    out = np.empty_like(a)
    fn = getattr(library(), f"round_array_{NARROW}_{instruction_set or isa()}")
    fn(address(a), address(out), a.size, Format.of(ar))
    return out


def round16(values: np.ndarray, ftz: bool) -> np.ndarray:
    """float32 values rounded to float16 by the kernels' rounding (for tests)."""
    a = np.ascontiguousarray(values, np.float32)
    out = np.empty_like(a)
    library().round16_array(address(a), address(out), a.size, int(ftz))
    return out
