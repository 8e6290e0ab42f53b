"""trace-diff on files that are not traces: exit 2 (trouble), never a traceback."""

from click.testing import CliRunner

from rend3r.cli import main

LINE = '{"pixel": [1, 2], "shape": 0, "stage": "t", "hex": "0x3c00", "dec": 1.0}\n'


def test_non_utf8_input_is_an_error_with_its_line(tmp_path):
    a = tmp_path / "a.jsonl"
    a.write_text(LINE)
    b = tmp_path / "b.jsonl"
    b.write_bytes(LINE.encode() + b"\xff\xfe binary\n")
    r = CliRunner().invoke(main, ["trace-diff", str(a), str(b)])
    assert r.exit_code == 2, r.output
    assert "b.jsonl:2: not UTF-8 text (byte 0xff)" in r.output and r.exception is not None
    assert not isinstance(r.exception, UnicodeDecodeError)


def test_exit_codes_follow_diff(tmp_path):
    a = tmp_path / "a.jsonl"
    a.write_text(LINE)
    b = tmp_path / "b.jsonl"
    b.write_text(LINE.replace("0x3c00", "0x3c01"))
    assert CliRunner().invoke(main, ["trace-diff", str(a), str(a)]).exit_code == 0
    assert CliRunner().invoke(main, ["trace-diff", str(a), str(b)]).exit_code == 1
    assert CliRunner().invoke(main, ["trace-diff", str(a), str(tmp_path / "none.jsonl")]).exit_code == 2
    assert "2 on trouble" in " ".join(CliRunner().invoke(main, ["trace-diff", "--help"]).output.split())
