"""Loading a program: assembly source, or any memory-image format the assembler writes;
the one loader of ``emulate``, ``send`` and ``render-all`` (what a file is comes from
:mod:`rend3r.asm.formats.recognise`, shared with ``asm`` and ``disasm``)."""

from __future__ import annotations

import os
import stat
from dataclasses import dataclass
from pathlib import Path

from ..asm.formats.recognise import kind_by_name, refuse_foreign_file
from ..errors import Rend3rError


@dataclass(frozen=True)
class LoadedProgram:
    """Words of a program and, for source, the mode its shape mnemonics imply."""

    words: list[int]
    mode_hint: str | None  # "raster" (source used tr), "raytrace" (source), None (words)


def load_program(path: str | os.PathLike[str]) -> LoadedProgram:
    """Assemble ``path`` if it is source (by suffix, or text no memory format accepts).

    A file whose suffix names a memory format (``.mem``, ``.bin``, ...) is only read as
    that format, so a malformed or oversized image is reported as such and never handed
    to the assembler; the size limits are the readers' (``rend3r.asm.formats.byte_limit``).
    A picture or an archive is refused by name, whatever its suffix.
    """
    p = Path(path)
    kind = kind_by_name(p)
    refuse_foreign_file(p)
    if kind == "source":
        return _assemble(p)
    from ..asm.formats import byte_limit, read_file

    try:
        return LoadedProgram(list(read_file(p)), None)
    except Rend3rError as as_image:
        if kind == "image" or not _small_regular_file(p, byte_limit(None)):
            raise
        try:
            return _assemble(p)
        except Rend3rError:
            raise as_image from None


def _small_regular_file(p: Path, limit: int) -> bool:
    """Whether ``p`` is a regular file of at most ``limit`` bytes (no FIFO, no device)."""
    try:
        st = p.stat()
    except OSError:
        return False
    return stat.S_ISREG(st.st_mode) and st.st_size <= limit


def _assemble(p: Path) -> LoadedProgram:
    from ..asm.assembler import assemble_or_raise

    result = assemble_or_raise(p)
    return LoadedProgram(list(result.program.words), result.mode)
