"""The Pareto front and the cheapest-format choice on made-up scores."""

import math

from rend3r.explore.campaign import Score, cheapest, design_cost
from rend3r.explore.report import pareto_front
from rend3r.precision.datapath import Resources


def score(psnr: float) -> Score:
    return Score(psnr, 0, 0.0, 0.0, 0.0)


COSTS = {"a": Resources(100, 10, 1), "b": Resources(200, 10, 1), "c": Resources(300, 10, 1),
         "d": Resources(400, 10, 2)}


def test_front_drops_dominated_formats():
    points = {"a": (COSTS["a"], 20.0), "b": (COSTS["b"], 18.0), "c": (COSTS["c"], 35.0), "d": (COSTS["d"], math.inf)}
    assert pareto_front(points) == ["a", "c", "d"]


def test_cheapest_meets_the_bound_at_least_cost():
    scores = {"a": score(20.0), "b": score(45.0), "c": score(40.0), "d": score(math.inf)}
    assert cheapest(scores, COSTS, 40.0) == "b"
    assert cheapest(scores, COSTS, 50.0) == "d"
    assert cheapest({"a": score(20.0)}, COSTS, 40.0) is None


def test_aliases_cost_as_their_formats():
    assert design_cost("bf16") == design_cost("e8m7")
    assert design_cost("fp16").dsp == design_cost("e5m7").dsp  # one DSP48E1 per multiplier below 25 bits
