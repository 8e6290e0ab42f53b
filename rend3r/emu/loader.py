"""Loading a program: assembly source, or any memory-image format the assembler writes."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import Rend3rError

SOURCE_SUFFIXES = (".asm", ".s", ".r3", ".rend3r")


@dataclass(frozen=True)
class LoadedProgram:
    """Words of a program and, for source, the mode its shape mnemonics imply."""

    words: list[int]
    mode_hint: str | None  # "raster" (source used tr), "raytrace" (source), None (words)


def load_program(path: str | os.PathLike[str]) -> LoadedProgram:
    """Assemble ``path`` if it is source (by suffix, or text no memory format accepts)."""
    p = Path(path)
    if p.suffix.lower() in SOURCE_SUFFIXES:
        return _assemble(p)
    from ..asm.formats import read_file

    try:
        return LoadedProgram(list(read_file(p)), None)
    except Rend3rError as as_image:
        try:
            return _assemble(p)
        except Rend3rError:
            raise as_image from None


def _assemble(p: Path) -> LoadedProgram:
    from ..asm.assembler import assemble_or_raise

    result = assemble_or_raise(p)
    used = result.mnemonics_used
    mode = "hybrid" if "ts" in used else "raster" if "tr" in used else "raytrace"
    return LoadedProgram(list(result.program.words), mode)
