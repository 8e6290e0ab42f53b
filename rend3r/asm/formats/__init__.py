"""Memory-image formats: render a :class:`Program` to bytes, read words back.

``FORMATS`` names every format with its default file extension. ``render`` writes one;
``read_words`` / ``read_file`` read any of them, detecting the format when it is not
given (see ``docs/formats.md``). Every malformed input raises :class:`Rend3rError` with a
``name:line:col:`` position (text formats) or a byte offset (``bin``).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO, Callable

from ...errors import Rend3rError
from ...fileio import read_limited
from ..program import Program
from .binary import read_bin, render_bin
from .coe import read_coe, render_coe
from .common import BYTES_PER_WORD, MAX_WORDS, check_byteorder, is_text
from .ihex import read_ihex, render_ihex
from .listing import read_lst, render_lst
from .mem import read_mem, render_mem, render_mem_annotated
from .recognise import HEAD, IMAGE_SUFFIXES, refuse_foreign


@dataclass(frozen=True)
class Format:
    """One output format: its name, default file extension and whether it is binary."""

    name: str
    extension: str
    binary: bool
    description: str


FORMATS: dict[str, Format] = {
    f.name: f
    for f in (
        Format("mem", ".mem", False, "$readmemh hex, one word per line (the original assembler's output)"),
        Format("mem-annotated", ".annotated.mem", False, "mem with // address and source comments"),
        Format("bin", ".bin", True, "raw 32-bit words, big-endian unless --byteorder little"),
        Format("coe", ".coe", False, "Xilinx memory coefficient file, radix 16"),
        Format("ihex", ".hex", False, "Intel HEX, byte address = word address * 4"),
        Format("lst", ".lst", False, "listing: line | address | word(s) | source"),
    )
}

_READERS: dict[str, Callable[[bytes, str, str], list[int]]] = {
    "mem": lambda data, name, order: read_mem(data, name),
    "mem-annotated": lambda data, name, order: read_mem(data, name),
    "bin": read_bin,
    "coe": lambda data, name, order: read_coe(data, name),
    "ihex": read_ihex,
    "lst": lambda data, name, order: read_lst(data, name),
}

#: Extensions that name one format (``rend3r.asm.formats.recognise``).
_EXTENSIONS = IMAGE_SUFFIXES


def _check_format(fmt: str) -> None:
    if fmt not in FORMATS:
        raise Rend3rError(f"unknown format {fmt!r}; choose from {', '.join(FORMATS)}")


def render(fmt: str, program: Program, byteorder: str = "big", *, ihex_record_bytes: int = 16) -> bytes:
    """The bytes of ``program`` in format ``fmt``.

    ``byteorder`` ("big" or "little") orders the bytes of each word in ``bin`` and
    ``ihex``; ``ihex_record_bytes`` is 16 (the usual record size) or 4 (one record per word).
    """
    _check_format(fmt)
    check_byteorder(byteorder)
    if fmt == "mem":
        return render_mem(program)
    if fmt == "mem-annotated":
        return render_mem_annotated(program)
    if fmt == "bin":
        return render_bin(program, byteorder)
    if fmt == "coe":
        return render_coe(program)
    if fmt == "ihex":
        return render_ihex(program, byteorder, ihex_record_bytes)
    return render_lst(program)


#: A row shaped ``... | HEX |``; the text before the first ``|`` is checked for ``//``
#: apart (a lookahead inside the repetition would cost memory per character).
_LST_ROW = re.compile(r"^([^|\n]*)\|\s*[0-9A-Fa-f]+\s*\|", re.M)
_COE_KEY = re.compile(r"memory_initialization_(?:radix|vector)\s*=", re.I)


def detect_format(data: bytes, name: str | None = None) -> str:
    """The reader for ``data``: by the extension of ``name`` when it names one format,
    else by content: binary data is ``bin``; text is ``ihex`` when its first non-blank
    line starts with ``:``, ``coe`` when it has a ``memory_initialization_...=`` key,
    ``lst`` when a row looks like ``line | address |``, and ``mem`` otherwise."""
    if name is not None:
        suffix = Path(name).suffix.lower()
        if suffix in _EXTENSIONS:
            return _EXTENSIONS[suffix]
    if not is_text(data):
        return "bin"
    text = data.decode("utf-8").removeprefix("\ufeff")
    first = len(text) - len(text.lstrip())  # where the first non-blank line starts
    if text.startswith(":", first):
        return "ihex"
    if _COE_KEY.search(text):
        return "coe"
    if not text.startswith(("//", "/*"), first) and any("//" not in m.group(1) for m in _LST_ROW.finditer(text)):
        return "lst"
    return "mem"


def byte_limit(fmt: str | None) -> int:
    """Largest file read as format ``fmt`` (any format when None): ``MAX_WORDS`` words at
    that format's ``BYTES_PER_WORD``."""
    return MAX_WORDS * (BYTES_PER_WORD[fmt] if fmt is not None else max(BYTES_PER_WORD.values()))


def read_words(data: bytes, fmt: str | None = None, name: str = "<input>", byteorder: str = "big") -> list[int]:
    """The words of a memory image in format ``fmt`` (detected from content when None).

    ``byteorder`` applies to ``bin`` and ``ihex``. Malformed input, more bytes than
    :func:`byte_limit` allows the format, or (when the format is not given) a picture or
    an archive (:func:`refuse_foreign`) raises Rend3rError.
    """
    check_byteorder(byteorder)
    if fmt is None:
        if not data:
            raise Rend3rError(f"{name}: empty file: no words")
        refuse_foreign(bytes(data[:HEAD]), name)
        fmt = detect_format(data)
    _check_format(fmt)
    if len(data) > byte_limit(fmt):
        raise Rend3rError(f"{name}: {fmt} image is {len(data):,} bytes; the limit is {byte_limit(fmt):,} bytes "
                          f"({MAX_WORDS:,} words of {BYTES_PER_WORD[fmt]} bytes)")
    return _READERS[fmt](data, name, byteorder)


def read_file(path: str | os.PathLike[str], fmt: str | None = None, byteorder: str = "big") -> list[int]:
    """Read a memory image file; the format is detected by extension, then by content (a
    picture or an archive is refused by name unless ``fmt`` is given).

    The file's size is checked before it is read (:func:`byte_limit` of the format its
    extension or ``fmt`` names, else of the largest), so a huge or endless file costs nothing.
    """
    name = os.fspath(path)
    known = fmt or _EXTENSIONS.get(Path(name).suffix.lower())
    if known is not None:
        _check_format(known)
    data = read_limited(path, byte_limit(known), what=f"{known or 'memory'} image")
    if fmt is None:
        if not data:
            raise Rend3rError(f"{name}: empty file: no words")
        refuse_foreign(data[:HEAD], name)
        fmt = detect_format(data, name)
    return read_words(data, fmt, name, byteorder)


def read_stream(stream: BinaryIO, fmt: str | None = None, name: str = "<stdin>", byteorder: str = "big") -> list[int]:
    """Read a memory image from ``stream`` (standard input), refused as soon as it passes
    :func:`byte_limit`, so an endless stream ends with an error."""
    limit = byte_limit(fmt)
    data = stream.read(limit + 1)
    if len(data) > limit:
        raise Rend3rError(f"{name}: {fmt or 'memory'} image is larger than the limit of {limit:,} bytes")
    return read_words(data, fmt, name, byteorder)


__all__ = ["FORMATS", "Format", "byte_limit", "detect_format", "read_file", "read_stream", "read_words", "render"]
