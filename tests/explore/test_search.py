"""explore --search: the greedy per-stage narrowing, design names, and the command end to end."""

import csv
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.cli import main
from rend3r.explore.campaign import Score, design_cost
from rend3r.explore.search import PARTS, design_name, greedy, split_design
from rend3r.precision.stages import STAGES

PROGRAMS = Path(__file__).parents[2] / "programs"
LADDER = ["fp32", "fp24", "fp16"]
CANONICAL = ["fp32", "e7m16", "fp16"]
#: dB each rung of a stage costs in the model scene below: the discriminant needs its bits.
LOSS = {"raster": 1.5, "camera": 1, "transform": 4, "quadratic": 3, "discriminant": 30, "sqrt": 2, "distance": 1, "hit": 2,
        "lighting": 1, "colour": 0.5}


def model(designs: list[str]) -> dict[str, list[Score]]:
    """Two programs whose PSNR falls by LOSS per rung narrowed (the second twice as fast)."""
    out = {}
    for d in designs:
        base, stages = split_design(d)
        rungs = {s: CANONICAL.index(dict(stages).get(s, base)) for s in STAGES} | {"raster": CANONICAL.index(base)}
        loss = sum(LOSS[s] * r for s, r in rungs.items())
        out[d] = [Score(90 - k * loss, 0, 0, 0, 0) for k in (1, 2)]
    return out


def test_design_names_read_back():
    name = design_name("fp32", {"sqrt": "fp16", "camera": "fp24", "hit": "fp32"})
    assert name == "fp32:camera=fp24+sqrt=fp16"
    assert split_design(name) == ("fp32", (("camera", "e7m16"), ("sqrt", "fp16")))  # canonical names
    assert split_design("e8m23") == ("fp32", ())
    for bad in ("fp32:", "fp32:sqrt", "fp32:colour=e12m2", "nope"):
        with pytest.raises(ValueError):
            split_design(bad)
    assert design_cost("fp32:sqrt=fp16").lut < design_cost("fp32").lut


def test_greedy_narrows_the_cheap_stages_and_keeps_the_bound():
    path = greedy(LADDER, 40.0, model, design_cost)
    assert path[0].design == "fp32" and path[0].stage is None
    assert all(step.worst_psnr >= 40 for step in path)
    assert [s.cost.lut for s in path] == sorted((s.cost.lut for s in path), reverse=True)
    assert len({s.cost.lut for s in path}) == len(path)  # every round saves
    base, stages = split_design(path[-1].design)
    final = {s: dict(stages).get(s, base) for s in STAGES}
    assert final["discriminant"] == "fp32"  # 30 dB a rung: never affordable at this bound
    assert base != "fp32"  # the base (the rasterizer's datapath) narrows too
    # no part can narrow one more rung without breaking the bound
    for part in PARTS:
        rung = CANONICAL.index(base if part == "raster" else final[part])
        if rung + 1 < len(LADDER):
            narrower = CANONICAL[rung + 1]
            worse = design_name(narrower, final) if part == "raster" else design_name(base, {**final, part: narrower})
            assert min(s.psnr for s in model([worse])[worse]) < 40, part


def test_greedy_stops_at_the_start_when_nothing_narrows():
    path = greedy(LADDER, 89.9, model, design_cost)
    assert [s.design for s in path] == ["fp32"]


def test_search_command_end_to_end(tmp_path):
    out = tmp_path / "s"
    r = CliRunner().invoke(main, ["explore", str(PROGRAMS / "sphere.asm"), "-o", str(out), "--search",
                                  "--ladder", "fp32,fp16,e5m4", "--min-psnr", "35", "--size", "16x12", "--quiet"])
    assert r.exit_code == 0, r.output
    with open(out / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    designs = [row["format"] for row in rows]
    assert designs[:3] == ["fp32", "fp16", "e5m4"]  # the uniform rungs first
    summary = (out / "summary.md").read_text()
    found = summary.split("Found: `")[1].split("`")[0]
    row = next(row for row in rows if row["format"] == found)
    assert float(row["psnr_db"]) >= 35 or math.isinf(float(row["psnr_db"]))
    assert len(designs) == len(set(designs)) > 3  # each design rendered once; the search went past the rungs
    meeting = [r for r in rows if float(r["psnr_db"]) >= 35]
    cheapest = min(meeting, key=lambda r: int(r["lut"]))
    assert f"| sphere | `{cheapest['format']}` |" in summary  # per program: the cheapest design visited


def test_search_refuses_formats_and_a_bad_ladder(tmp_path):
    base = ["explore", str(PROGRAMS / "sphere.asm"), "-o", str(tmp_path / "x"), "--search", "--size", "8x6"]
    r = CliRunner().invoke(main, [*base, "--formats", "fp16"])
    assert r.exit_code == 2 and "give --ladder, not --formats" in r.output
    r = CliRunner().invoke(main, [*base, "--ladder", "fp16,fp32"])
    assert r.exit_code == 2 and "widest first" in r.output
    assert not (tmp_path / "x").exists()


def test_pareto_of_many_designs_names_the_front_only():
    import xml.etree.ElementTree as ET

    from rend3r.explore.campaign import ProgramSpec
    from rend3r.explore.report import MAX_LABELS, Results, pareto_front, pareto_svg

    designs = [design_name("fp32", {s: "fp16" for s in STAGES[:k]}) for k in range(len(STAGES) + 1)]
    designs += [design_name("fp16", {s: "fp32" for s in STAGES[:k]}) for k in range(1, 6)]
    assert len(designs) > MAX_LABELS
    spec = ProgramSpec("p", (), "raytrace", 1)
    scores = {("p", d): s[0] for d, s in model(designs).items()}
    costs = {d: design_cost(d) for d in designs}
    r = Results([spec], designs, scores, costs, 40.0, "ftz", (8, 6))
    root = ET.fromstring(pareto_svg(r))
    ns = {"s": "http://www.w3.org/2000/svg"}
    assert len(root.findall("s:circle", ns)) == len(designs)
    named = {t.text for t in root.findall("s:text", ns)} & set(designs)
    front = pareto_front({d: (costs[d], scores["p", d].psnr) for d in designs})
    assert named == set(front)
