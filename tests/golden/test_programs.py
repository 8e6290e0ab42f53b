"""The example programs assemble cleanly and together use every instruction and property."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import pytest

from rend3r.asm.assembler import AssemblyResult, assemble_file
from rend3r.golden.catalog import discover, read_header
from rend3r.isa import PROPERTIES, CameraSet, FrameOp, LightSet, ShapeSet, Table, decode_stream

PROGRAMS_DIR = Path(__file__).resolve().parents[2] / "programs"
PROGRAMS = discover(PROGRAMS_DIR)

@lru_cache(maxsize=None)
def assembled(path: Path) -> AssemblyResult:
    return assemble_file(path)


#: Warnings a program provokes on purpose (program name -> substring).
EXPECTED_WARNINGS = {"registers": "second value wins"}


@pytest.mark.parametrize("program", PROGRAMS, ids=[p.name for p in PROGRAMS])
def test_program_assembles(program) -> None:
    result = assembled(program.path)
    assert result.ok, result.format_diagnostics()
    text = result.format_diagnostics()
    if program.name in EXPECTED_WARNINGS:
        assert EXPECTED_WARNINGS[program.name] in text
    else:
        assert "warning" not in text, text


def test_programs_cover_every_instruction_and_property() -> None:
    used: dict[Table, set[int]] = {t: set() for t in Table}
    funcs = set()
    for program in PROGRAMS:
        words = list(assembled(program.path).program.words)
        table = Table.TRIANGLE if program.mode == "raster" else Table.SHAPE
        for _, ins in decode_stream(words):
            if isinstance(ins, FrameOp):
                funcs.add(ins.func.name.lower())
            elif isinstance(ins, CameraSet):
                used[Table.CAMERA].add(ins.prop)
            elif isinstance(ins, LightSet):
                used[Table.LIGHT].add(ins.prop)
            elif isinstance(ins, ShapeSet):
                used[table] |= {ins.prop, ins.prop2}
    assert funcs == {"nr", "nf", "lr", "er"}
    for table, props in PROPERTIES.items():
        missing = {p.name for p in props} - {p.name for p in props if p.index in used[table]}
        assert not missing, f"no program sets {table.value} properties {sorted(missing)}"


def test_header_keys(tmp_path: Path) -> None:
    p = tmp_path / "x.asm"
    p.write_text("; x.asm: test\n; frames: 3\n;   mode: Raster\n; test-size: 16x12\nnr\n; frames: 9\n", encoding="utf-8")
    h = read_header(p)
    assert (h.frames, h.mode, h.test_size) == (3, "raster", (16, 12))
    assert (h.frame_name(0), h.frame_name(2)) == ("x.000", "x.002")
