"""The program a view serves: loaded once at start and again whenever its files change.

A source is assembled with the assembler's own :func:`assemble_file`, so its diagnostics
keep their file, line, column and span; a failed reload keeps the last good words. The
files watched are those the last assembly read or looked for (``AssemblyResult.files``:
the program and every ``.include``, also one that only defines names or was not found).
"""

from __future__ import annotations

import hashlib
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..asm.formats.recognise import kind_by_name
from ..errors import Rend3rError

#: A change is read once the files have stood still this long: an editor's save may
#: truncate a file and then write it, and the half-way file is not the program.
SETTLE_S = 0.05


@dataclass(frozen=True)
class Good:
    """A program that loaded: its words (REND3R) or its octree (``.svo``)."""

    words: tuple[int, ...] = ()
    mode: str = "raytrace"
    svo: object | None = field(default=None, compare=False)  # rend3r.svo.fileformat.SvoModel
    digest: str = ""  # an octree's bytes, hashed: two loads of the same .svo compare equal


@dataclass
class State:
    """What the view shows: the last good program, and the current diagnostics."""

    version: int = 0  # counts loads that changed the program
    good: Good | None = None
    diagnostics: list[dict] = field(default_factory=list)
    message: str = ""  # the diagnostics as the command line prints them ("" when the program loads)


def diagnostic_json(d) -> dict:
    """One :class:`rend3r.asm.diagnostics.Diagnostic` as JSON, with its printed form."""
    return {"severity": d.severity, "message": d.message, "file": d.file, "line": d.line, "col": d.col,
            "end": d.end, "text": d.text, "context": list(d.context), "formatted": d.format()}


class ProgramSource:
    """The program file of a view and the files it depends on."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.kind = "svo" if self.path.suffix.lower() == ".svo" else "rend3r"
        self.state = State()
        self._files: set[Path] = {self.path}
        self._signature: tuple = ()
        self._lock = threading.Lock()

    def signature(self) -> tuple:
        """(path, mtime, size) of every watched file (None, None for one missing)."""
        out = []
        for f in sorted(self._files):
            try:
                st = f.stat()
            except OSError:
                out.append((str(f), None, None))
            else:
                out.append((str(f), st.st_mtime_ns, st.st_size))
        return tuple(out)

    def refresh(self) -> bool:
        """Reload when a watched file changed; True when what the view shows changed
        (new words, or diagnostics appeared, changed or went away)."""
        with self._lock:
            signature = self.signature()
            if signature == self._signature:
                return False
            time.sleep(SETTLE_S)
            if self.signature() != signature:
                return False  # still being written: the next look reads it
            self._signature = signature
            before = (self.state.good, self.state.message)
            self._load()
            return (self.state.good, self.state.message) != before

    def _load(self) -> None:
        try:
            good, diagnostics, message = self._read()
        except Rend3rError as exc:
            good, diagnostics, message = None, [], str(exc)
        if good is not None and good != self.state.good:
            self.state.good = good
            self.state.version += 1
        self.state.diagnostics, self.state.message = diagnostics, message

    def _read(self) -> tuple[Good | None, list[dict], str]:
        if self.kind == "svo":
            from ..svo.fileformat import read_svo

            model = read_svo(self.path)
            digest = hashlib.sha256(model.tree.words.tobytes() + repr(model.bounds).encode()).hexdigest()
            return Good(svo=model, digest=digest), [], ""
        if kind_by_name(self.path) != "source":
            from ..emu.loader import load_program

            return Good(tuple(load_program(self.path).words)), [], ""
        from ..asm.assembler import MAX_ERRORS, assemble_file
        from ..asm.formats.recognise import refuse_foreign_file

        refuse_foreign_file(self.path)
        result = assemble_file(self.path, max_errors=MAX_ERRORS)
        self._files = {self.path, *result.files}
        diagnostics = [diagnostic_json(d) for d in result.diagnostics]
        if not result.ok:
            return None, diagnostics, result.format_diagnostics()
        return Good(tuple(result.program.words), result.mode), diagnostics, ""
