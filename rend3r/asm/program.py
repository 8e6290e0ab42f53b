"""What the assembler produces: words with the source each came from.

Shared by the assembler (which builds it), the output formats (listing, annotated mem)
and the disassembler (which builds one from words alone).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, slots=True)
class SourceLoc:
    """A position in a source file; line and column count from 1."""

    file: str
    line: int
    col: int = 1

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.col}"


@dataclass(frozen=True, slots=True)
class Emitted:
    """The word(s) one source statement produced, at its address."""

    address: int
    words: tuple[int, ...]
    loc: SourceLoc | None = None
    text: str = ""  # the source line, without its newline


@dataclass
class Program:
    """An assembled program: statements in address order."""

    entries: list[Emitted] = field(default_factory=list)

    @property
    def words(self) -> list[int]:
        return [w for e in self.entries for w in e.words]
