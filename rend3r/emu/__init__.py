"""The REND3R emulator: instruction processor, float16 raytracer and rasterizer.

Public API::

    from rend3r.emu import load_program, run_program, Frame, EmuOptions
    prog = load_program("programs/sphere.asm")
    result = run_program(prog.words, options=EmuOptions(precision="fp16"), frames=None)
    result.frames[0].rgb565  # (H, W) uint16

Submodules load numpy on import; ``rend3r.emu`` itself imports them lazily.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .frame import Frame
    from .loader import LoadedProgram, load_program
    from .options import EmuOptions
    from .run import RunResult, run_program

_EXPORTS = {
    "Frame": ".frame",
    "EmuOptions": ".options",
    "LoadedProgram": ".loader",
    "load_program": ".loader",
    "RunResult": ".run",
    "run_program": ".run",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(_EXPORTS[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
