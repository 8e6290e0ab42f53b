"""rend3r explore on two small programs in three formats."""

import csv
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.cli import main
from rend3r.explore.report import COLUMNS

PROGRAMS = Path(__file__).parents[2] / "programs"
ARGS = [str(PROGRAMS / "sphere.asm"), str(PROGRAMS / "shadow.asm"), "--size", "32x24"]
FORMATS = "e4m3,bf16,fp32"


def explore(out: Path, *extra: str):
    return CliRunner().invoke(main, ["explore", *ARGS, "-o", str(out), "--formats", FORMATS, *extra])


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("explore") / "out"
    r = explore(out, "--min-psnr", "28")
    assert r.exit_code == 0, r.output
    with open(out / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return out, rows


def summary_choices(out: Path) -> dict[str, str]:
    """program -> cheapest format meeting the bound, from summary.md's first table."""
    lines = (out / "summary.md").read_text().splitlines()
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in lines if line.startswith("| ")]
    return {c[0]: c[2] for c in cells if c[1] in ("raytrace", "raster", "hybrid")}


def test_csv_has_a_row_per_program_and_format(run):
    out, rows = run
    assert tuple(rows[0]) == COLUMNS
    assert [(r["program"], r["format"]) for r in rows] == [
        (p, f) for p in ("sphere", "shadow") for f in FORMATS.split(",")]
    assert sorted(p.name for p in out.iterdir()) == ["pareto.svg", "results.csv", "summary.md"]


def test_fp32_scores_higher_than_e4m3_and_costs_more(run):
    _, rows = run
    for program in ("sphere", "shadow"):
        by = {r["format"]: r for r in rows if r["program"] == program}
        assert float(by["fp32"]["psnr_db"]) > float(by["e4m3"]["psnr_db"])
        assert int(by["fp32"]["lut"]) > int(by["bf16"]["lut"]) > int(by["e4m3"]["lut"])
        assert float(by["e4m3"]["provenance_share"]) > 0  # e4m3's coarse grid moves silhouettes


def test_cheapest_choice_respects_min_psnr(run):
    out, rows = run
    choices = summary_choices(out)
    for program in ("sphere", "shadow"):
        meeting = [r for r in rows if r["program"] == program and float(r["psnr_db"]) >= 28]
        assert all(r["meets_min_psnr"] == "1" for r in meeting)
        expected = min(meeting, key=lambda r: int(r["lut"]))["format"] if meeting else "none"
        assert choices[program] == expected
    assert set(choices.values()) != {"e4m3"}  # the bound excluded something


@pytest.mark.parametrize("bound, expected", [("0", "e4m3"), ("500", "none")])
def test_a_bound_everything_or_nothing_meets(tmp_path, bound, expected):
    r = CliRunner().invoke(main, ["explore", *ARGS, "-o", str(tmp_path), "--formats", "e4m3,bf16",
                                  "--min-psnr", bound])
    assert r.exit_code == 0, r.output
    assert set(summary_choices(tmp_path).values()) == {expected}


def test_pareto_svg_parses_and_marks_every_format(run):
    out, _ = run
    root = ET.parse(out / "pareto.svg").getroot()
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    ns = {"s": "http://www.w3.org/2000/svg"}
    assert len(root.findall("s:circle", ns)) == 3
    labels = {t.text for t in root.findall("s:text", ns)}
    assert {"e4m3", "bf16", "fp32"} <= labels


@pytest.mark.parametrize("formats", ["e4m3,fp99", "e1m3", "fp16-ftz", ""])
def test_a_bad_format_exits_2(tmp_path, formats):
    r = CliRunner().invoke(main, ["explore", *ARGS, "-o", str(tmp_path / "o"), "--formats", formats])
    assert r.exit_code == 2
    assert "--formats" in r.output
    assert not (tmp_path / "o").exists()


def test_a_failing_program_leaves_no_output(tmp_path):
    bad = tmp_path / "bad.asm"
    bad.write_text("nr\nsp 0, nosuchprop, 1\nnf\ner\ner\n")
    out = tmp_path / "out" / "deeper"
    r = CliRunner().invoke(main, ["explore", str(PROGRAMS / "sphere.asm"), str(bad), "-o", str(out),
                                  "--size", "8x6", "--formats", "e4m3"])
    assert r.exit_code == 1
    assert "error" in r.output and "bad.asm" in r.output
    assert not (tmp_path / "out").exists()


def test_a_program_without_frames_is_an_error_and_writes_nothing(tmp_path):
    empty = tmp_path / "empty.asm"
    empty.write_text("nr\ner\ner\n")
    r = CliRunner().invoke(main, ["explore", str(empty), "-o", str(tmp_path / "o"), "--size", "8x6",
                                  "--formats", "e4m3"])
    assert r.exit_code == 1
    assert "rend3r: error: empty in fp64: empty: rendered no frame" in r.output
    assert not (tmp_path / "o").exists()


def test_help_has_an_example():
    r = CliRunner().invoke(main, ["explore", "--help"])
    assert r.exit_code == 0
    assert "Example:" in r.output and "rend3r explore programs/*.asm -o out/explore" in r.output


def test_identical_formats_score_inf(tmp_path):
    r = CliRunner().invoke(main, ["explore", str(PROGRAMS / "sphere.asm"), "-o", str(tmp_path), "--size", "16x12",
                                  "--formats", "fp64", "-q"])
    assert r.exit_code == 0 and r.output == ""
    row = next(csv.DictReader((tmp_path / "results.csv").read_text().splitlines()))
    assert math.isinf(float(row["psnr_db"])) and row["max_channel"] == "0"


def test_a_campaign_over_the_memory_budget_is_refused_before_rendering(tmp_path):
    """8192x8192 keeps 6 bytes a pixel of fp64 reference per program: over 1 GiB it is
    refused up front, with the estimate and the option named, and nothing is written."""
    out = tmp_path / "x"
    r = CliRunner().invoke(main, ["explore", str(PROGRAMS / "sphere.asm"), str(PROGRAMS / "shadow.asm"), "-o",
                                  str(out), "--size", "8192x8192", "--max-memory", "1G", "--scheduler", "none"])
    assert r.exit_code == 1
    assert "GiB" in r.output and "--max-memory" in r.output
    assert not out.exists()
