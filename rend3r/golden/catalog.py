"""The example programs under ``programs/`` and the metadata in their comment headers.

A program's header may carry ``; key: value`` lines read by tools:

- ``frames: N``: frames to render (default 1); programs that loop with ``lr`` need it;
- ``mode: raytrace|raster|hybrid``: rendering mode (default: the emulator's hint from the source);
- ``test-size: WxH``: a smaller image size for the test suite, for scenes too slow to test
  at the golden size.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..cliutil import parse_size
from ..errors import Rend3rError

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


MODES = ("raytrace", "raster", "hybrid")


def read_header(path: Path) -> ExampleProgram:
    """Metadata from the leading comment block of ``path``.

    Rend3rError (``path:line: ...``) for a file that is not UTF-8 text or a header value
    that is malformed; an unreadable header is never ignored.
    """
    try:
        text = path.read_bytes().decode("utf-8")
    except OSError as exc:
        raise Rend3rError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        line = exc.object[: exc.start].count(b"\n") + 1
        raise Rend3rError(f"{path}:{line}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x})") from None
    frames, mode, test_size = 1, None, None
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if stripped and not stripped.startswith((";", "//")):
            break
        m = _HEADER_KEY.match(line)
        if not m:
            continue
        key, value = m.group(1).lower(), m.group(2)
        where = f"{path}:{number}"
        if key == "frames":
            if not value.isascii() or not value.isdigit() or int(value) < 1:
                raise Rend3rError(f"{where}: frames: expected a whole number >= 1, not {value!r}")
            frames = int(value)
        elif key == "mode":
            mode = value.lower()
            if mode not in MODES:
                raise Rend3rError(f"{where}: mode: expected {', '.join(MODES)}, not {value!r}")
        else:
            try:
                test_size = parse_size(value)
            except ValueError as exc:
                raise Rend3rError(f"{where}: test-size: {exc}") from None
    return ExampleProgram(path, frames, mode, test_size)


def program_paths(directory: Path) -> list[Path]:
    """Every ``*.asm`` directly in ``directory``, sorted by name."""
    return sorted(directory.glob("*.asm"))


def discover(directory: Path) -> list[ExampleProgram]:
    """Every ``*.asm`` directly in ``directory`` (sorted by name), with its metadata."""
    return [read_header(p) for p in program_paths(directory)]
