"""``rend3r view`` over plain HTTP: endpoints against the emulator's own output, live
reload, diagnostics, and the safety cases (a real server on a free loopback port)."""

from __future__ import annotations

import asyncio
import io
import json
import os
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rend3r.cli import main

from .conftest import SPHERE, serve, wait_for

ROOT = Path(__file__).resolve().parents[2]


def _trace_cli(program: Path, tmp_path: Path, pixel: str, *args: str) -> list[dict]:
    """The records ``rend3r emulate --trace-pixel`` prints."""
    result = CliRunner().invoke(main, ["emulate", str(program), "-o", str(tmp_path / "f.png"), "-q",
                                       "--trace-pixel", pixel, *args])
    assert result.exit_code == 0, result.output
    return [json.loads(line) for line in result.output.splitlines() if line.startswith("{")]


def _png(body: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(body)).convert("RGB"))


TRACE_FIELDS = ("frame", "pixel", "shape", "stage", "hex", "dec")


@pytest.mark.parametrize("query, cli", [
    ("", ()),
    ("precision=e6m9&subnormals=ieee", ("--precision", "e6m9", "--subnormals", "ieee")),
    ("profile=rend3r-2022", ("--profile", "rend3r-2022")),
])
def test_pixel_history_is_the_trace_of_emulate_with_fp64_beside_it(tmp_path, query, cli):
    program = ROOT / "programs" / "shadow.asm"
    with serve(program) as s:
        status, h = s.json(f"/api/pixel?x=250&y=200&{query}")
    assert status == 200, h
    want = _trace_cli(program, tmp_path, "250,200", *cli)
    assert [{k: r[k] for k in TRACE_FIELDS} for r in h["records"]] == want
    ref = {(r["shape"], r["stage"]): r for r in _trace_cli(program, tmp_path, "250,200", *cli, "--precision", "fp64")}
    for r in h["records"]:
        f = ref.get((r["shape"], r["stage"]))
        assert r["fp64"] == (None if f is None else {"hex": f["hex"], "dec": f["dec"]})
    first = h["first_divergence"]
    assert first is not None and h["records"][first]["diverges"]
    assert not any(r["diverges"] for r in h["records"][:first])
    hit = [r["shape"] for r in want if r["stage"] == "hit" and r["dec"] == 1]
    nearest = next(r["dec"] for r in want if r["stage"] == "nearest")
    assert sorted(x["shape"] for x in h["hits"]) == hit and h["hits"][0]["shape"] == nearest
    assert "lower shape index" in h["tie_rule"]


def test_the_first_divergence_is_the_first_value_off_fp64_rounded(tmp_path):
    """In fp64 nothing diverges; in fp16 a value marked equal is the fp64 value rounded."""
    program = ROOT / "programs" / "fp16_cancel.asm"
    with serve(program) as s:
        _, same = s.json("/api/pixel?x=256&y=192&precision=fp64")
        _, h = s.json("/api/pixel?x=256&y=192")
    assert same["first_divergence"] is None and not any(r["diverges"] for r in same["records"])
    for r in h["records"]:
        if r["fp64"] is not None and not isinstance(r["dec"], int) and not r["diverges"]:
            assert np.float16(float(r["fp64"]["dec"])) == np.float16(float(r["dec"])) or r["dec"] == "nan"


def test_frames_are_emulates_and_the_difference_counts_the_pixels_that_differ(tmp_path):
    program = ROOT / "programs" / "animation.asm"
    with serve(program) as s:
        status, info = s.json("/api/frame?frame=2&size=128x96&precision=bf16")
        assert status == 200 and info["frames"] == 64 and info["frame"] == 2, info
        frame = _png(s.request("/api/image/frame.png?frame=2&size=128x96&precision=bf16")[2])
        ref = _png(s.request("/api/image/fp64.png?frame=2&size=128x96&precision=bf16")[2])
        heat = _png(s.request("/api/image/diff.png?frame=2&size=128x96&precision=bf16")[2])
    result = CliRunner().invoke(main, ["emulate", str(program), "-o", str(tmp_path / "f{n}.png"), "-q",
                                       "--frames", "3", "--size", "128x96", "--precision", "bf16"])
    assert result.exit_code == 0, result.output
    want = np.asarray(Image.open(tmp_path / "f2.png").convert("RGB"))
    assert np.array_equal(frame, want)
    differs = np.abs(frame.astype(int) - ref.astype(int)).max(axis=2) > 0
    assert info["differing_pixels"] == int(differs.sum()) > 0
    assert np.array_equal(heat.any(axis=2), differs)


def test_raster_and_device_quirks_and_a_frame_outside_the_program(tmp_path):
    program = ROOT / "programs" / "tri_cube.asm"
    with serve(program) as s:
        _, h = s.json("/api/pixel?x=256&y=192&quirk=raster-pixel-snap&depth=painter")
        assert h["mode"] == "raster" and h["hits"] is None and "painter" in h["tie_rule"]
        assert [{k: r[k] for k in TRACE_FIELDS} for r in h["records"]] == _trace_cli(
            program, tmp_path, "256,192", "--device-quirk", "raster-pixel-snap", "--depth", "painter")
        status, err = s.json("/api/frame?frame=1")
        assert status == 400 and "frame 1 is outside 0..0" in err["error"]


def test_a_large_scene_lists_the_hit_shapes_unless_all_are_asked_for():
    program = ROOT / "programs" / "stress4096.asm"
    with serve(program) as s:
        _, h = s.json("/api/pixel?x=32&y=24&size=64x48")
        _, every = s.json("/api/pixel?x=32&y=24&size=64x48&shapes=all")
    assert h["shapes"] == every["shapes"] == 4096
    assert 0 < h["shapes_shown"] < 64 and every["shapes_shown"] == 4096
    nearest = next(r for r in h["records"] if r["stage"] == "nearest")["dec"]
    assert any(r["shape"] == nearest and r["stage"] == "hit" for r in h["records"])
    assert len(every["records"]) > 4096 * 20


def _status(s) -> dict:
    return s.json("/api/status")[1]


def test_live_reload_pushes_over_the_websocket_and_keeps_the_last_good_frame_on_errors(sphere_program):
    from tornado.websocket import websocket_connect

    with serve(sphere_program) as s:
        red = _png(s.request("/api/image/frame.png?size=64x48")[2])

        async def messages(edit_to: str) -> dict:
            ws = await websocket_connect(f"ws://127.0.0.1:{s.port}/api/live")
            hello = json.loads(await ws.read_message())
            sphere_program.write_text(edit_to)
            msg = json.loads(await asyncio.wait_for(ws.read_message(), 20))
            ws.close()
            return hello, msg

        hello, msg = asyncio.run(messages(SPHERE.replace("COLOUR", "0x07E0")))
        assert hello["type"] == "hello" and msg["type"] == "reload" and msg["version"] == hello["version"] + 1
        green = _png(s.request("/api/image/frame.png?size=64x48")[2])
        assert green[24, 32, 1] > 0 and red[24, 32, 1] == 0 and red[24, 32, 0] > 0

        _, msg = asyncio.run(messages(SPHERE.replace("COLOUR", "0x07E0").replace("sp 0, zloc", "sp 0, zlok")))
        assert not msg["ok"] and msg["loaded"] and msg["version"] == hello["version"] + 1
        (d,) = msg["diagnostics"]
        assert (d["file"], d["line"], d["col"], d["severity"]) == (str(sphere_program), 7, 7, "error")
        assert d["text"] == "sp 0, zlok, rrot, -3, 1" and "^~~~" in d["formatted"] and "zlok" in d["message"]
        assert msg["message"].startswith(f"{sphere_program}:7:7: error:")
        status, kind, body = s.request("/api/image/frame.png?size=64x48")
        assert status == 200 and np.array_equal(_png(body), green)
    assert "Traceback" not in s.stderr_text and "rend3r view:" not in s.stderr_text


def test_the_files_the_assembler_read_are_watched(tmp_path):
    """An include in another folder that only defines names, and one created after the
    program failed for want of it (the assembler's AssemblyResult.files)."""
    (tmp_path / "lib").mkdir()
    inc = tmp_path / "lib" / "colour.asm"
    inc.write_text("COLOUR = 0xF800\n")
    main_file = tmp_path / "scene.asm"
    main_file.write_text('.include "lib/colour.asm"\n' + SPHERE)
    with serve(main_file) as s:
        assert _status(s)["ok"]
        inc.write_text('.include "shade.asm"\n')
        st = wait_for(lambda: not (st := _status(s))["ok"] and st)
        assert "cannot find include file 'shade.asm'" in st["message"]
        (tmp_path / "lib" / "shade.asm").write_text("COLOUR = 0x001F\n")
        assert wait_for(lambda: _status(s)["ok"])
        blue = _png(s.request("/api/image/frame.png?size=64x48")[2])
        assert blue[24, 32, 2] > 0 and blue[24, 32, 0] == 0


def test_a_program_broken_from_the_start_shows_its_diagnostics_and_no_frame(tmp_path):
    bad = tmp_path / "bad.asm"
    bad.write_text("nr\ncam bogus, 1\ner\ner\n")
    with serve(bad) as s:
        st = _status(s)
        assert not st["ok"] and not st["loaded"]
        assert st["diagnostics"][0]["line"] == 2 and st["diagnostics"][0]["col"] == 5
        assert f"{bad}:2:5: error: unknown camera property 'bogus'" in st["message"]
        status, err = s.json("/api/frame")
        assert status == 409 and "not loaded" in err["error"]
    assert f"{bad}:2:5: error" in s.stderr_text


def test_svo_render_cost_and_a_rays_traversal(tmp_path):
    obj, svo = tmp_path / "torus.obj", tmp_path / "torus.svo"
    for args in (["svo", "model", "torus", "-o", str(obj), "-q"], ["svo", "build", str(obj), "-o", str(svo), "--depth", "5", "-q"]):
        result = CliRunner().invoke(main, args)
        assert result.exit_code == 0, result.output
    png = tmp_path / "cli.png"
    CliRunner().invoke(main, ["svo", "render", str(svo), "-o", str(png), "--size", "80x60", "-q",
                              "--cost", str(tmp_path / "cost.png")])
    with serve(svo) as s:
        assert _status(s)["kind"] == "svo"
        render = _png(s.request("/api/svo/image/render.png?size=80x60")[2])
        cost = _png(s.request("/api/svo/image/cost.png?size=80x60")[2])
        assert np.array_equal(render, np.asarray(Image.open(png).convert("RGB")))
        assert np.array_equal(cost[..., 0], np.asarray(Image.open(tmp_path / "cost.png").convert("L")))
        y, x = np.argwhere(render.any(axis=2))[0]
        _, ray = s.json(f"/api/svo/ray?size=80x60&x={x}&y={y}")
        _, miss = s.json("/api/svo/ray?size=80x60&x=0&y=0")
        status, err = s.json("/api/frame")
    assert ray["hit"] and len(ray["nodes"]) == ray["requests"] == ray["cost"] > 1
    assert ray["pushes"] >= ray["max_level"] > 0 and ray["nodes"][0] == {"address": 0, "level": 0}
    assert not miss["hit"] and miss["requests"] == miss["cost"]
    assert status == 404 and ".svo" in err["error"]


# -- safety ---------------------------------------------------------------------------

BAD_PATHS = ["/static/../../../etc/passwd", "/static/%2e%2e/%2e%2e/etc/passwd", "/static//etc/passwd",
             "/../etc/passwd", "/static/..%2f..%2fserver.py", "/static/server.py", "/etc/passwd",
             "/static/%2fetc%2fpasswd", "/api/source/../../etc/passwd", "//etc/passwd"]


def test_only_the_pages_own_files_and_the_program_are_served(tmp_path, sphere_program):
    outside = tmp_path / "outside.txt"
    outside.write_text("secret-content")
    static = ROOT / "rend3r" / "view" / "static"
    link = static / "link.js"
    try:
        os.symlink(outside, link)
    except OSError:
        link = None
    try:
        with serve(sphere_program) as s:
            for path in BAD_PATHS + [f"/static/{outside}", "/static/link.js"]:
                status, kind, body = s.request(path)
                assert 400 <= status < 500, (path, status)
                assert kind.startswith("application/json") and "error" in json.loads(body), path
                assert b"secret-content" not in body and b"root:" not in body and b"Traceback" not in body
            status, kind, body = s.request("/static/app.js")
            assert status == 200 and kind.startswith("text/javascript")
            status, kind, body = s.request("/api/source")
            assert status == 200 and body.decode() == sphere_program.read_text()
    finally:
        if link is not None:
            link.unlink()


@pytest.mark.parametrize("query, status, words", [
    ("/api/frame?size=4096x4096", 413, "at most 1,048,576"),
    ("/api/frame?size=0x5", 400, "size"),
    ("/api/frame?precision=e99m3", 400, "precision"),
    ("/api/frame?precision=" + "9" * 5000, 400, "at most 64 characters"),
    ("/api/frame?subnormals=maybe", 400, "subnormals"),
    ("/api/frame?quirk=warp-drive", 400, "unknown device quirk"),
    ("/api/frame?profile=rend3r-2022&subnormals=ieee", 400, "contradicts quirk flush-subnormals"),
    ("/api/frame?quirk=raster-index-order&depth=painter", 400, "contradicts quirk raster-index-order"),
    ("/api/frame?depth=sideways", 400, "depth"),
    ("/api/frame?frame=-1", 400, "frame"),
    ("/api/frame?frame=99999999999", 400, "frame"),
    ("/api/frame?frame=1&frame=2", 400, "once"),
    ("/api/pixel?x=64&y=0&size=64x48", 400, "x 64 is outside 0..63"),
    ("/api/pixel?x=a&y=0", 400, "integer"),
    ("/api/pixel?y=0", 400, "x is required"),
    ("/api/pixel?x=%ff&y=0", 400, ""),
    ("/api/pixel?x=0&y=0&shapes=some", 400, "shapes: hit or all"),
    ("/api/svo/ray?x=0&y=0", 404, ".svo"),
    ("/api/image/other.png", 404, "no such page"),
])
def test_bad_requests_get_4xx_and_a_json_error(shared, query, status, words):
    got, body = shared.json(query)
    assert got == status and words in body["error"] and body["status"] == status, body
    assert shared.json("/api/status")[0] == 200  # and the server still serves


def test_other_methods_get_405_and_a_json_error(shared):
    import http.client

    conn = http.client.HTTPConnection("127.0.0.1", shared.port, timeout=60)
    conn.request("POST", "/api/status", body=b"x" * 1000, headers={"Host": f"127.0.0.1:{shared.port}"})
    r = conn.getresponse()
    assert r.status == 405 and json.loads(r.read())["status"] == 405
    conn.close()


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    """One server for the table of bad requests."""
    p = tmp_path_factory.mktemp("shared") / "scene.asm"
    p.write_text(SPHERE.replace("COLOUR", "0xF800"))
    with serve(p) as s:
        yield s
    assert "Traceback" not in s.stderr_text and "internal error" not in s.stderr_text


def test_a_request_naming_another_host_is_refused(sphere_program):
    with serve(sphere_program) as s:
        status, kind, body = s.request("/api/status", host="attacker.example:80")
        assert status == 403 and b"not this server" in body
        assert s.request("/api/status", host=f"localhost:{s.port}")[0] == 200


def test_another_address_needs_the_printed_token(sphere_program):
    with serve(sphere_program, "--host", "0.0.0.0") as s:
        token = s.url.split("token=", 1)[1]
        assert len(token) >= 20
        for path in ("/api/status", "/api/status?token=wrong", "/", "/api/image/frame.png"):
            status, kind, body = s.request(path)
            assert status == 403 and b"token" in body, path
        assert s.request(f"/api/status?token={token}")[0] == 200
        assert s.request(f"/?token={token}")[0] == 200
        assert s.request("/static/style.css")[0] == 200  # the page's own files carry nothing of the program
