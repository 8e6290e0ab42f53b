"""Run the self-checking ISA conformance sources in ``asm/`` (see ``asm/README.md``).

Markers in a line's trailing comment:
  ``; => 0x... [0x...]``     the words this line emits (all .rept iterations, in order)
  ``; error: TEXT``          an error on this line whose message contains TEXT (no ';')
  ``; warning: TEXT``        a warning on this line whose message contains TEXT
(a line may carry several: ``; => 0x00000801 ; warning: underflows``)
and on lines of their own:
  ``;! target NAME``         assemble with ``--target NAME``
  ``;! werror``              assemble with ``-W error``
  ``;! isa-ext NAME``        assemble with ``--isa-ext NAME``
  ``;! file-warning: TEXT``  a warning about the whole program (no line)
A line without ``=>`` must emit nothing, and every diagnostic must be expected.
"""

from __future__ import annotations

import re
from collections import defaultdict
from pathlib import Path

import pytest

from rend3r.asm.assembler import assemble_file

ROOT = Path(__file__).resolve().parents[2] / "asm"
SOURCES = sorted(ROOT.glob("*.asm"))

_WORDS = re.compile(r";\s*=>\s*((?:0x[0-9a-f]{8}\s*)+)")
_DIAG = re.compile(r";\s*(error|warning):\s*([^;]+?)\s*(?=;|$)")
_PRAGMA = re.compile(r"^;!\s*(target\s+(\S+)|werror|file-warning:\s*(.+?)|isa-ext\s+(\S+))\s*$")


def _markers(path: Path) -> tuple[dict[int, list[int]], dict[int, list[tuple[str, str]]]]:
    words, diags = {}, defaultdict(list)
    for n, line in enumerate(path.read_text(encoding="utf-8").split("\n"), 1):
        if line.lstrip().startswith(";!"):
            continue
        if m := _WORDS.search(line):
            words[n] = [int(w, 16) for w in m.group(1).split()]
        diags[n].extend(_DIAG.findall(line))
    return words, diags


def test_suite_is_present():
    assert len(SOURCES) >= 10


@pytest.mark.parametrize("path", SOURCES, ids=[p.name for p in SOURCES])
def test_conformance(path: Path):
    target, werror, file_warnings, isa_ext = None, False, [], []
    for line in path.read_text(encoding="utf-8").split("\n"):
        if m := _PRAGMA.match(line.strip()):
            if m.group(2):
                target = m.group(2)
            elif m.group(4):
                isa_ext.append(m.group(4))
            elif m.group(1) == "werror":
                werror = True
            else:
                file_warnings.append(m.group(3))
    result = assemble_file(path, include_paths=[ROOT / "include"], target=target, werror=werror, isa_ext=isa_ext)

    emitted: dict[tuple[str, int], list[int]] = defaultdict(list)
    for entry in result.program.entries:
        emitted[(Path(entry.loc.file).resolve().as_posix(), entry.loc.line)].extend(entry.words)
    files = {path.resolve().as_posix()} | {f for f, _ in emitted} | {
        Path(d.file).resolve().as_posix() for d in result.diagnostics if d.line
    }
    expected_diags: dict[tuple[str, int], list[tuple[str, str]]] = {}
    for f in files:
        words, diags = _markers(Path(f))
        for n, ws in words.items():
            assert emitted.pop((f, n), []) == ws, f"{Path(f).name}:{n}: words"
        for n, ds in diags.items():
            expected_diags[(f, n)] = list(ds)
    leftover = {k: v for k, v in emitted.items() if k[0] in files}
    assert not leftover, f"lines emitted words without a '=>' marker: {leftover}"

    unexpected = []
    for d in result.diagnostics:
        if not d.line:
            match = next((t for t in file_warnings if t in d.message and d.severity == "warning"), None)
            if match is None:
                unexpected.append(d.format())
            else:
                file_warnings.remove(match)
            continue
        wanted = expected_diags.get((Path(d.file).resolve().as_posix(), d.line), [])
        match = next(((s, t) for s, t in wanted if s == d.severity and t in d.message), None)
        if match is None:
            unexpected.append(d.format())
        else:
            wanted.remove(match)
    missing = {k: v for k, v in expected_diags.items() if v}
    assert not unexpected, "unexpected diagnostics:\n" + "\n".join(unexpected)
    assert not missing, f"expected diagnostics not produced: {missing}"
    assert not file_warnings, f"expected file warnings not produced: {file_warnings}"
