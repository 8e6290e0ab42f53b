"""docs/isa.md carries exactly what ``python -m rend3r.isa.doc`` prints."""

import subprocess
import sys
from pathlib import Path

from rend3r.isa.doc import BEGIN, END, LAYOUTS, _cells, generated_block
from rend3r.isa.tables import PROPERTIES

DOC = Path(__file__).resolve().parents[2] / "docs" / "isa.md"


def test_doc_contains_the_generated_block_verbatim():
    text = DOC.read_text()
    assert text.count(BEGIN) == 1 and text.count(END) == 1
    start, end = text.index(BEGIN), text.index(END) + len(END)
    assert text[start:end] == generated_block(), "docs/isa.md is stale: paste `python -m rend3r.isa.doc` into it"


def test_module_prints_the_block():
    out = subprocess.run([sys.executable, "-m", "rend3r.isa.doc"], capture_output=True, text=True, check=True).stdout
    assert out == generated_block() + "\n"


def test_every_property_appears():
    block = generated_block()
    for props in PROPERTIES.values():
        for p in props:
            assert f"| {p.index} | `{p.name}` | `{p.register}` |" in block


def test_layouts_cover_32_bits():
    for name, fields, zero_mask in LAYOUTS:
        cells = _cells(fields, zero_mask)
        assert sum(hi - lo + 1 for hi, lo, _ in cells) == 32, name
