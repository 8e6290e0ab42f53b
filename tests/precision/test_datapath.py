"""Operation counts of the datapaths, against a hand count of docs/emulator.md section 4."""

from rend3r.precision.cost import operator_cost
from rend3r.precision.datapath import raster_counts, raytrace_counts
from rend3r.precision.formats import parse


def test_ray_shape_test_counts_as_the_hand_count():
    # docs/emulator.md section 4, one ray against one sphere with a rotation that is not the identity:
    # 1. translate S' = S - L                         3 add
    # 2. conj(q) * (0, v): 3 mul + 2 add per part (the b0 products are exact)  12 mul  8 add
    #    (.) * q, vector part only: 4 mul + 3 add per part                     12 mul  9 add
    #    for S' and for D                                                      48 mul 34 add
    # 3. inverse scale of S and D                     6 mul
    # 4. a2 = 2(D.D): 3 mul 2 add + 1 doubling        3 mul  3 add
    #    b = 2(D.S)                                   3 mul  3 add
    #    c2 = 2((Sx^2 + Sy^2) + (Sz^2 - 1))           3 mul  4 add
    # 5. disc = b*b - a2*c2                           2 mul  1 add
    #    root, t1 = (-b - root)/a2, t2 = (-b + root)/a2   1 sqrt  2 add  2 div
    # per stage, the primary ray's test and the shadow ray's (one shadow ray against one shape: the same test)
    hand = {"transform": {"add": 3 + 34, "mul": 48 + 6}, "quadratic": {"add": 3 + 3 + 4, "mul": 3 + 3 + 3},
            "discriminant": {"add": 1, "mul": 2}, "sqrt": {"add": 2, "div": 2, "sqrt": 1}}
    counts = raytrace_counts()
    for stage, ops in hand.items():
        assert counts.stages[stage] == {op: 2 * n for op, n in ops.items()}, stage


def test_distance_surface_and_lighting_counts():
    s = raytrace_counts().stages
    # 7. sq_dist = ((dx*dx + dy*dy) + dz*dz) * (t*t)
    assert s["distance"] == {"add": 2, "mul": 5}
    # 8. hit point and object point: 3 mul 3 add each; normal scaled (3 mul), rotated (24 mul 17 add)
    assert s["hit"] == {"add": 23, "mul": 33}
    # section 5: l = light - point (3), n.n and l.l and n.l (3 dots), 2 sqrt, denominator, cos; f (colour)
    assert s["lighting"] == {"add": 3 + 6, "mul": 9 + 1, "div": 1, "sqrt": 2}
    assert s["colour"] == {"mul": 1}
    raster = raster_counts().stages["lighting"]
    assert raster == {op: s["lighting"].get(op, 0) + s["colour"].get(op, 0) for op in raster}


def test_camera_rotation_is_counted():
    # a rotated camera: q normalised (4 mul, 3 add, 1 sqrt, 4 div), each direction rotated (24 mul, 17 add)
    ray, raster = raytrace_counts().stages, raster_counts().stages
    assert ray["camera"]["add"] == 3 + 17 and ray["camera"]["sqrt"] == 1 and ray["camera"]["div"] == 4
    assert raster["to_camera"] == {"add": 3 + 17, "mul": 24}  # translate, then rotate each vertex


def test_totals_sum_the_stages_and_cost_sums_the_units():
    for counts in (raytrace_counts(), raster_counts()):
        for op, n in counts.total.items():
            assert n == sum(stage.get(op, 0) for stage in counts.stages.values())
    counts, fp16 = raytrace_counts(), parse("fp16")
    expected = sum(n * operator_cost(op, fp16).lut for op, n in counts.total.items())
    assert counts.cost(fp16).lut == expected
    assert counts.cost(fp16).dsp == counts.total["mul"]  # one DSP48E1 per fp16 multiplier
    assert counts.cost(parse("fp32")).lut > counts.cost(fp16).lut > counts.cost(parse("e4m3")).lut


def test_staged_cost_prices_each_stage_in_its_format():
    counts, fp16, fp32 = raytrace_counts(), parse("fp16"), parse("fp32")
    wide = counts.cost(fp16, {"discriminant": fp32})
    extra = sum(n * (operator_cost(op, fp32).lut - operator_cost(op, fp16).lut)
                for op, n in counts.stages["discriminant"].items())
    assert wide.lut == counts.cost(fp16).lut + extra > counts.cost(fp16).lut
    assert counts.cost(fp16, {stage: fp32 for stage in counts.stages}) == counts.cost(fp32)
