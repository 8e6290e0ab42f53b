"""Request parameters: every query value checked, bounded and turned into emulator options.

A bad value is a :class:`RequestError` (HTTP 400 with a JSON message), never an exception
the server did not expect.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from ..cliutil import parse_size
from ..errors import Rend3rError

#: Largest frame a request may ask for, in pixels (1024x1024; the device's is 512x384).
MAX_PIXELS = 1 << 20
#: Longest query value read (a precision name, a quirk name, a size).
MAX_VALUE = 64
#: Most ``quirk`` values in one request (there are 16 quirks).
MAX_QUIRKS = 32
#: Most frames a view shows of a program (``--frames``: a looping program shows this many).
MAX_FRAMES = 4096

Args = Mapping[str, Sequence[bytes]]


class RequestError(Exception):
    """A request the view refuses; ``status`` is the HTTP status (4xx)."""

    def __init__(self, message: str, status: int = 400) -> None:
        super().__init__(message)
        self.status = status


def values(args: Args, name: str) -> list[str]:
    """Every value of query parameter ``name``, decoded and length-checked."""
    out = []
    for raw in args.get(name, ()):
        if len(raw) > MAX_VALUE:
            raise RequestError(f"{name}: at most {MAX_VALUE} characters")
        try:
            out.append(raw.decode("ascii"))
        except UnicodeDecodeError:
            raise RequestError(f"{name}: ASCII expected") from None
    return out


def one(args: Args, name: str, default: str | None = None) -> str | None:
    """The single value of ``name`` (``default`` when absent; given twice is an error)."""
    got = values(args, name)
    if len(got) > 1:
        raise RequestError(f"{name} given {len(got)} times; give it once")
    return got[0] if got else default


def integer(args: Args, name: str, lo: int, hi: int, default: int | None = None) -> int:
    """An integer parameter in [lo, hi]."""
    text = one(args, name)
    if text is None:
        if default is None:
            raise RequestError(f"{name} is required")
        return default
    if not (text.isascii() and text.lstrip("-").isdigit() and len(text) <= 10):
        raise RequestError(f"{name}: expected an integer, not {text!r}")
    value = int(text)
    if not lo <= value <= hi:
        raise RequestError(f"{name} {value} is outside {lo}..{hi}")
    return value


def number(args: Args, name: str, lo: float, hi: float, default: float) -> float:
    """A finite decimal parameter in [lo, hi]."""
    text = one(args, name)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        raise RequestError(f"{name}: expected a number, not {text!r}") from None
    if not lo <= value <= hi:  # False for NaN too
        raise RequestError(f"{name} {text} is outside {lo:g}..{hi:g}")
    return value


def size(args: Args, default: str) -> tuple[int, int]:
    """``size=WxH``, at most :data:`MAX_PIXELS` pixels."""
    text = one(args, "size", default)
    try:
        w, h = parse_size(text)
    except ValueError as exc:
        raise RequestError(f"size: {exc}") from None
    if w * h > MAX_PIXELS:
        raise RequestError(f"size {w}x{h} is {w * h:,} pixels; the view renders at most {MAX_PIXELS:,} "
                           f"(e.g. 1024x1024)", 413)
    return w, h


def emu_options(args: Args, mode: str):
    """The :class:`rend3r.emu.options.EmuOptions` a request names: ``precision``,
    ``subnormals``, ``depth``, ``profile``, ``quirk`` (repeatable) and ``size``, checked as
    ``rend3r emulate`` checks its options."""
    from ..emu.arith import precision_name
    from ..emu.options import EmuOptions
    from ..emu.quirks import apply_quirks, contradictions, quirk_names

    try:
        precision = precision_name(one(args, "precision", "fp16"))
    except ValueError as exc:
        raise RequestError(f"precision: {exc}") from None
    subnormals = one(args, "subnormals")
    if subnormals not in (None, "ftz", "ieee"):
        raise RequestError(f"subnormals: ftz or ieee, not {subnormals!r}")
    depth = one(args, "depth")
    if depth not in (None, "zbuffer", "painter"):
        raise RequestError(f"depth: zbuffer or painter, not {depth!r}")
    profile = one(args, "profile") or None
    quirks = values(args, "quirk")
    if len(quirks) > MAX_QUIRKS:
        raise RequestError(f"quirk: at most {MAX_QUIRKS} values")
    try:
        selected = quirk_names(profile, quirks)
    except Rend3rError as exc:
        raise RequestError(str(exc)) from None
    given = {k: v for k, v in (("subnormals", subnormals), ("depth", depth)) if v is not None}
    for field, quirk, value in contradictions(given, selected):
        raise RequestError(f"{field} {given[field]} contradicts quirk {quirk}, which sets {value}")
    w, h = size(args, "512x384")
    options = EmuOptions(precision=precision, subnormals=subnormals or "ftz", mode=mode, width=w, height=h,
                         depth=depth or "zbuffer")
    return apply_quirks(options, selected)
