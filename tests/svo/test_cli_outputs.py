"""svo outputs: checked before any work, missing folders made; render writes PNG only."""

import pytest
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main


def _run(*args):
    return CliRunner().invoke(main, ["svo", *map(str, args)])


@pytest.fixture(scope="module")
def svo(tmp_path_factory):
    d = tmp_path_factory.mktemp("svo")
    assert _run("model", "sphere", "-o", d / "s.ply", "--detail", "8").exit_code == 0
    assert _run("build", d / "s.ply", "-o", d / "s.svo", "--depth", "4").exit_code == 0
    return d / "s.svo"


def test_render_writes_png_and_cost(svo, tmp_path):
    r = _run("render", svo, "-o", tmp_path / "a.png", "--cost", tmp_path / "c.png", "--size", "12x8")
    assert r.exit_code == 0, r.output
    assert Image.open(tmp_path / "a.png").size == (12, 8) and Image.open(tmp_path / "c.png").format == "PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "c.png"]


@pytest.mark.parametrize(("args", "why"), [
    (["-o", "{t}/x.jpg"], "unknown image type '.jpg'"),
    (["-o", "{t}/a.png", "--cost", "{t}/c"], "unknown image type '(no extension)'"),
    (["-o", "{t}/a.png", "--with-program", "programs/sphere.asm", "--cost", "{t}/c.gif"], "unknown image type '.gif'"),
])
def test_bad_outputs_are_refused_before_rendering(svo, tmp_path, args, why):
    r = _run("render", svo, *(a.format(t=tmp_path) for a in args), "--size", "12x8")
    assert r.exit_code == 1 and why in r.output, r.output
    assert list(tmp_path.iterdir()) == []


def test_sizes_use_the_shared_limit(svo, tmp_path):
    for cmd in ("render", "sweep"):
        r = _run(cmd, svo, "-o", tmp_path / "x.png", "--size", "100000x1")
        assert r.exit_code == 2 and "1..8192" in r.output, r.output


def test_missing_folders_are_made(svo, tmp_path):
    r = _run("render", svo, "-o", tmp_path / "a" / "b" / "x.png", "--size", "12x8")
    assert r.exit_code == 0, r.output
    assert Image.open(tmp_path / "a" / "b" / "x.png").size == (12, 8)


@pytest.mark.parametrize("cmd", [
    ["model", "sphere"], ["build", "{svo}"], ["render", "{svo}"], ["sweep", "{svo}"]])
def test_an_output_that_cannot_be_written_is_refused_first(svo, tmp_path, cmd):
    (tmp_path / "file").write_text("not a folder")
    name = {"model": "m.obj", "build": "m.svo", "render": "m.png", "sweep": "m"}[cmd[0]]
    args = [a.format(svo=svo) for a in cmd] + ["-o", tmp_path / "file" / name]
    r = _run(*args, "--size", "12x8") if cmd[0] in ("render", "sweep") else _run(*args)
    assert r.exit_code == 1 and "cannot write" in r.output and "file" in r.output, r.output
    assert [p.name for p in tmp_path.iterdir()] == ["file"]
