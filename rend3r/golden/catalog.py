"""The example programs under ``programs/`` and the metadata in their comment headers.

A program's header may carry ``; key: value`` lines read by tools:

- ``frames: N``: frames to render (default 1); programs that loop with ``lr`` need it;
- ``mode: raster|raytrace``: rendering mode (default: the emulator's hint from the source);
- ``test-size: WxH``: a smaller image size for the test suite, for scenes too slow to test
  at the golden size.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

_HEADER_KEY = re.compile(r"^\s*;\s*(frames|mode|test-size)\s*:\s*(\S+)\s*$", re.IGNORECASE)


@dataclass(frozen=True)
class ExampleProgram:
    """One ``programs/*.asm`` file and its header metadata."""

    path: Path
    frames: int = 1
    mode: str | None = None
    test_size: tuple[int, int] | None = None

    @property
    def name(self) -> str:
        return self.path.stem

    def frame_name(self, frame: int) -> str:
        """File stem for one frame: ``name`` for a single-frame program, else ``name.NNN``."""
        return self.name if self.frames == 1 else f"{self.name}.{frame:03d}"


def _parse_size(text: str) -> tuple[int, int]:
    w, h = text.lower().split("x")
    return int(w), int(h)


def read_header(path: Path) -> ExampleProgram:
    """Metadata from the leading comment block of ``path``."""
    frames, mode, test_size = 1, None, None
    for line in path.read_text(encoding="utf-8").splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith((";", "//")):
            break
        m = _HEADER_KEY.match(line)
        if not m:
            continue
        key, value = m.group(1).lower(), m.group(2)
        if key == "frames":
            frames = int(value)
        elif key == "mode":
            mode = value.lower()
        else:
            test_size = _parse_size(value)
    return ExampleProgram(path, frames, mode, test_size)


def discover(directory: Path) -> list[ExampleProgram]:
    """Every ``*.asm`` directly in ``directory`` (sorted by name), with its metadata."""
    return [read_header(p) for p in sorted(directory.glob("*.asm"))]
