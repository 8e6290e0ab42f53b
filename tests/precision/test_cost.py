"""The hardware cost model: it reproduces the measured fp16 operators exactly, never gets
cheaper as a format widens, lands on the vendor's published single-precision figures within
the stated factors, and the table in docs/precision.md is what it computes."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rend3r.precision import FloatFormat, parse
from rend3r.precision.cost import FP16_ANCHORS, OPERATORS, operator_cost

# Single precision on 7-series, the vendor's Floating-Point Operator (PG060): maximum
# latencies per operation, and the DSP48E1 count of the multiplier between its "full" and
# "max" DSP usage. Cited in docs/precision.md with the factor each is held to.
PUBLISHED_FP32_LATENCY = {"add": 11, "mul": 8, "div": 28, "sqrt": 28, "compare": 2}
PUBLISHED_FP32_MUL_DSP = (2, 3)
LATENCY_FACTOR = 1.25


@pytest.mark.parametrize("subnormals", ["ftz", "ieee"])
def test_fp16_reproduces_the_measured_anchors(subnormals: str) -> None:
    fmt = parse("fp16", subnormals)
    for op, anchor in FP16_ANCHORS.items():
        assert operator_cost(op, fmt) == anchor, op
    assert operator_cost("sub", fmt) == FP16_ANCHORS["add"]


def test_no_figure_shrinks_as_a_format_widens() -> None:
    for op in OPERATORS:
        for e in range(2, 12):
            for m in range(1, 53):
                here = operator_cost(op, FloatFormat(e, m))
                wider = [FloatFormat(e, m + 1)] if m < 52 else []
                wider += [FloatFormat(e + 1, m)] if e < 11 else []
                for w in wider:
                    there = operator_cost(op, w)
                    assert (there.latency >= here.latency and there.lut >= here.lut
                            and there.ff >= here.ff and there.dsp >= here.dsp), (op, e, m, w)


def test_fp32_within_the_stated_factor_of_published_figures() -> None:
    fp32 = parse("fp32")
    for op, published in PUBLISHED_FP32_LATENCY.items():
        modelled = operator_cost(op, fp32).latency
        assert published / LATENCY_FACTOR <= modelled <= published * LATENCY_FACTOR, (op, modelled, published)
    low, high = PUBLISHED_FP32_MUL_DSP
    assert low <= operator_cost("mul", fp32).dsp <= high
    assert operator_cost("div", parse("fp64")).latency == 57  # 53 bits + 4, as the IP's double


def test_unknown_operator() -> None:
    with pytest.raises(ValueError, match="unknown operator 'fma'"):
        operator_cost("fma", parse("fp16"))


def test_the_table_in_the_docs_is_the_model() -> None:
    doc = (Path(__file__).parents[2] / "docs" / "precision.md").read_text()
    rows = re.findall(r"^\| (\w+) \| ((?:\d+ / \d+ / \d+ / \d+ \| ?)+)$", doc, flags=re.MULTILINE)
    assert len(rows) >= 8
    ops = [op for op in OPERATORS if op != "sub"]
    for name, cells in rows:
        figures = [tuple(map(int, c.split(" / "))) for c in cells.strip(" |").split(" | ")]
        want = [tuple(vars(operator_cost(op, parse(name))).values()) for op in ops]
        assert figures == want, name
