"""Option parsing shared by the commands: image sizes ``WxH``, thread counts."""

from __future__ import annotations

import re

import click

#: Largest width or height any command renders or reads (bounds memory: 8192x8192 RGB565).
MAX_SIDE = 8192

_SIZE = re.compile(r"\s*([0-9]+)\s*[xX]\s*([0-9]+)\s*", re.ASCII)


def parse_size(text: str, max_side: int = MAX_SIDE) -> tuple[int, int]:
    """``"WxH"`` -> (W, H), each side 1..``max_side``; ValueError with a clear reason otherwise."""
    m = _SIZE.fullmatch(text)
    if not m:
        raise ValueError(f"expected WIDTHxHEIGHT such as 512x384, not {text!r}")
    w, h = int(m[1]), int(m[2])
    if not (1 <= w <= max_side and 1 <= h <= max_side):
        raise ValueError(f"width and height must be 1..{max_side}, not {text!r}")
    return w, h


class SizeType(click.ParamType):
    """A click parameter type for ``WxH`` image sizes (bad values exit 2, as bad options do)."""

    name = "WxH"

    def convert(self, value, param, ctx) -> tuple[int, int]:
        if isinstance(value, tuple):
            return value
        try:
            return parse_size(str(value))
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


#: The shared instance: ``@click.option("--size", type=SIZE, default="512x384")``.
SIZE = SizeType()


#: ``--jobs N``: threads rendering each frame (0, the default: every core this process may use).
JOBS = click.option("--jobs", type=click.IntRange(0, 256), default=0, show_default=True, metavar="N",
                    help="Threads rendering each frame; 0 uses every core. The image does not depend on it.")
