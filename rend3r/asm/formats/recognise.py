"""What a program file is, decided the same way by every command (asm, disasm, emulate,
send): assembly source by its suffix, a memory image by its suffix, and a picture or an
archive by its first bytes, which is refused by name rather than read as words."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from ...errors import Rend3rError

#: Suffixes of assembly source: ours and the original project's ``.rdr``.
SOURCE_SUFFIXES = frozenset({".asm", ".rdr", ".s", ".r3", ".rend3r"})

#: Extensions that name one memory-image format. ``.hex`` is absent on purpose: it is used
#: both for Intel HEX and for ``$readmemh`` files, so such files are told apart by content.
IMAGE_SUFFIXES = {".mem": "mem", ".bin": "bin", ".coe": "coe", ".ihex": "ihex", ".ihx": "ihex", ".lst": "lst"}

#: Leading bytes of files that are neither source nor a memory image, and what they are.
_FOREIGN = (
    (b"\x89PNG\r\n\x1a\n", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"GIF87a", "a GIF image"),
    (b"GIF89a", "a GIF image"),
    (b"PK\x03\x04", "a ZIP archive"),
    (b"PK\x05\x06", "a ZIP archive"),
)
#: Bytes read to recognise a file by content.
HEAD = 8


def kind_by_name(path: str | os.PathLike[str]) -> Literal["source", "image"] | None:
    """"source" or "image" when ``path``'s suffix says so; None when only content can tell."""
    suffix = Path(path).suffix.lower()
    if suffix in SOURCE_SUFFIXES:
        return "source"
    if suffix in IMAGE_SUFFIXES:
        return "image"
    return None


def refuse_foreign(head: bytes, name: str) -> None:
    """Refuse, by name, data that starts like a picture or an archive (``x.png is a PNG image``)."""
    for magic, what in _FOREIGN:
        if head.startswith(magic):
            raise Rend3rError(f"{name} is {what}, not a REND3R program (source or memory image)")


def refuse_foreign_file(path: str | os.PathLike[str]) -> None:
    """:func:`refuse_foreign` on the first bytes of a regular file (others are left to their reader)."""
    if not os.path.isfile(path):  # a FIFO or a device is not opened twice (nor waited on)
        return
    try:
        with open(path, "rb") as fh:
            head = fh.read(HEAD)
    except OSError:
        return  # the reader that follows reports it with its own words
    refuse_foreign(head, os.fspath(path))


def refuse_wrong_kind(path: str | os.PathLike[str], wanted: Literal["source", "image"]) -> None:
    """Refuse a file whose suffix says it is the other kind, or whose bytes say it is neither."""
    kind = kind_by_name(path)
    if kind == "image" and wanted == "source":
        raise Rend3rError(f"{path} is a memory image, not assembly source (rend3r disasm reads it)")
    if kind == "source" and wanted == "image":
        raise Rend3rError(f"{path} is assembly source, not a memory image (rend3r asm assembles it)")
    refuse_foreign_file(path)
