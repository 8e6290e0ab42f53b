"""The ``rend3r view`` command line: help, refusals, the printed URL, Ctrl-C."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from click.testing import CliRunner

from rend3r.cli import main

from .conftest import serve


def test_help_has_an_example_and_the_options():
    result = CliRunner().invoke(main, ["view", "--help"])
    assert result.exit_code == 0
    assert "rend3r view programs/shadow.asm" in result.output
    for option in ("--port N", "--host H", "--open"):
        assert option in result.output


def test_frames_bounds_a_looping_program_and_is_checked():
    program = str(Path(__file__).resolve().parents[2] / "programs" / "animation.asm")
    with serve(program, "--frames", "8") as s:
        assert s.json("/api/frame?size=32x24")[1]["frames"] == 8
        status, err = s.json("/api/frame?size=32x24&frame=8")
        assert status == 400 and "frame 8 is outside 0..7" in err["error"]
    bad = CliRunner().invoke(main, ["view", program, "--frames", "0"])
    assert bad.exit_code == 2 and "--frames" in bad.output


def test_a_missing_program_is_refused_before_listening(tmp_path):
    result = CliRunner().invoke(main, ["view", str(tmp_path / "none.asm"), "--port", "0"])
    assert result.exit_code == 1 and f"rend3r: error: {tmp_path / 'none.asm'}: no such file" in result.output


def test_a_port_in_use_is_an_error_naming_it(sphere_program):
    with serve(sphere_program) as s:
        result = subprocess.run([sys.executable, "-m", "rend3r", "view", str(sphere_program), "--port", str(s.port)],
                                capture_output=True, text=True, timeout=60)
    assert result.returncode == 1 and f"rend3r: error: cannot listen on 127.0.0.1:{s.port}" in result.stderr
    assert "Traceback" not in result.stderr


def test_it_prints_its_url_and_ctrl_c_stops_it_with_130_and_no_traceback(sphere_program):
    with serve(sphere_program) as s:
        assert s.first_line.startswith(f"rend3r view: serving {sphere_program} at http://127.0.0.1:")
        assert s.json("/api/status")[1]["ok"]
    assert s.proc.returncode == 130
    assert s.stderr_text.strip() == "rend3r: interrupted"


def test_view_loads_tornado_only_when_it_runs():
    code = "import sys; from rend3r.cli import main; import rend3r.view.cli; print('tornado' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
