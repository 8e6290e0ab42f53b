"""The rend3r command group: lazy commands, start-up cost, how user errors are printed."""

import subprocess
import sys
from pathlib import Path

from click.testing import CliRunner

from rend3r.cli import COMMANDS, main


def test_every_registered_command_loads_and_has_an_example():
    for name in COMMANDS:
        result = CliRunner().invoke(main, [name, "--help"])
        assert result.exit_code == 0, (name, result.output)
        assert "Example" in result.output or "example" in result.output, name


#: The commands that write files, and what their -o/--output names.
WRITERS = {"asm": "FILE|STEM", "disasm": "FILE", "emulate": "PATTERN", "send": "FILE", "device": "DIR",
           "render-all": "DIR", "compare": "FILE"}


def test_every_command_that_writes_takes_dash_o_with_a_metavar_saying_what():
    for name, metavar in WRITERS.items():
        result = CliRunner().invoke(main, [name, "--help"])
        assert f"-o, --output {metavar} " in result.output, (name, result.output)


def test_every_size_option_reads_wxh():
    for name in ("emulate", "device", "render-all", "compare"):
        result = CliRunner().invoke(main, [name, "--help"])
        assert "--size WxH " in result.output, name
        args = ["a", "b"] if name == "compare" else ["-o", "x"]
        bad = CliRunner().invoke(main, [name, *args, "--size", "12"])
        assert bad.exit_code == 2 and "expected WIDTHxHEIGHT such as 512x384, not '12'" in bad.output, (name, bad.output)


def test_help_imports_no_heavy_module():
    code = "import sys; from rend3r.cli import main; print(sorted({'numpy', 'scapy', 'PIL', 'lark'} & set(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_source_diagnostics_are_printed_once_without_a_second_prefix(tmp_path):
    src = tmp_path / "bad.asm"
    src.write_text("nr\ncam bogus, 1\ner\ner\n")
    for args in (["emulate", str(src), "-o", str(tmp_path / "x.png")], ["send", str(src), "-o", str(tmp_path / "x.mem")]):
        result = CliRunner().invoke(main, args)
        assert result.exit_code == 1
        assert "rend3r: error:" not in result.output
        assert f"{src}:2:5: error: unknown camera property 'bogus'" in result.output
        assert result.output.count("unknown camera property") == 1
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "x.mem").exists()


def test_ctrl_c_exits_130_without_a_traceback_or_output(tmp_path):
    """SIGINT mid-run (disasm waiting on a pipe that stays open): exit 130 as shells report
    it, one line, and no output file."""
    import signal
    import time

    out = tmp_path / "out.asm"
    proc = subprocess.Popen([sys.executable, "-m", "rend3r", "disasm", "-", "-o", str(out)],
                            stdin=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc.stdin.write("3c000000\n")
    proc.stdin.flush()
    time.sleep(1.5)  # past start-up: reading standard input, which never ends
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err
    assert not out.exists()


def test_sigterm_mid_run_leaves_no_staged_file(tmp_path):
    """SIGTERM while an animation's frames are staged: exit 143, one line, and neither
    the frames nor their staged parts nor the folder the run made remain."""
    import signal
    import time

    folder = tmp_path / "frames"
    prog = Path(__file__).resolve().parents[1] / "programs" / "animation.asm"
    proc = subprocess.Popen([sys.executable, "-m", "rend3r", "emulate", str(prog), "--frames", "20000",
                             "--precision", "fp32", "-o", str(folder / "f_{n:05}.png")], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not (folder.exists() and any(folder.iterdir())) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)  # until the first frame is staged
    assert proc.poll() is None, "the run ended before it was terminated"
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert "Traceback" not in err and "rend3r: terminated" in err
    assert not folder.exists()


def test_ctrl_c_while_a_command_loads_exits_130(monkeypatch):
    """Ctrl-C during the lazy import of a command's module: exit 130 and one line, not
    click's 'Aborted!' with status 1."""
    import importlib

    def interrupt(name, *args):
        raise KeyboardInterrupt

    monkeypatch.setattr(importlib, "import_module", interrupt)
    result = CliRunner().invoke(main, ["emulate", "--help"])
    assert result.exit_code == 130
    assert "rend3r: interrupted" in result.output and "Aborted" not in result.output


def test_exit_statuses_follow_one_convention(tmp_path):
    """0 success, 1 an error, 2 a bad command line (130 for Ctrl-C: above)."""
    src = tmp_path / "s.asm"
    src.write_text("nr\ner\ner\n")
    assert CliRunner().invoke(main, ["asm", str(src)]).exit_code == 0
    assert CliRunner().invoke(main, ["asm", str(tmp_path / "missing.asm")]).exit_code == 1
    assert CliRunner().invoke(main, ["asm", str(src), "--no-such-option"]).exit_code == 2
    assert CliRunner().invoke(main, ["no-such-command"]).exit_code == 2


def test_running_out_of_memory_is_one_clear_error(tmp_path):
    """A 65,536-sphere run in a process whose address space ends 64 MiB past what it has
    after loading the command (the budget told to allow it): one error line, exit 1, no
    traceback, no image."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import walls

    program = tmp_path / "wall.mem"
    program.write_text("".join(f"{int(w):08x}\n" for w in walls.wall(65536, lights=1).words))
    code = ("import resource, sys, numpy\n"
            "from rend3r.cli import main\n"
            "import rend3r.emu.cli, rend3r.emu.run, rend3r.emu.loader\n"
            "size = int(open('/proc/self/statm').read().split()[0]) * resource.getpagesize()\n"
            "resource.setrlimit(resource.RLIMIT_AS, (size + (64 << 20), resource.RLIM_INFINITY))\n"
            "main(sys.argv[1:])\n")
    out = tmp_path / "out.png"
    run = subprocess.run([sys.executable, "-c", code, "emulate", str(program), "-o", str(out), "--jobs", "1",
                          "--max-memory", "100G", "--quiet"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 1, (run.returncode, run.stderr)
    assert run.stderr.startswith("rend3r: error: out of memory") and "Traceback" not in run.stderr, run.stderr
    assert not out.exists()
