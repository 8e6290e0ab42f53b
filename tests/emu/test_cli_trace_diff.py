"""trace-diff on files that are not traces: exit 2 (trouble), never a traceback."""

import pytest
from click.testing import CliRunner

from rend3r.cli import main
from rend3r.emu.trace_diff import MAX_TRACE

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


def _diff(tmp_path, text, other=LINE):
    a = tmp_path / "a.jsonl"
    a.write_text(other)
    b = tmp_path / "b.jsonl"
    b.write_bytes(text.encode() if isinstance(text, str) else text)
    return CliRunner().invoke(main, ["trace-diff", str(a), str(b)])


def test_deep_nesting_is_refused_with_file_line_and_column(tmp_path):
    r = _diff(tmp_path, LINE + "[" * 100_000 + "\n")
    assert r.exit_code == 2 and "b.jsonl:2:17: JSON nested deeper than 16 levels" in r.output, r.output
    assert not isinstance(r.exception, RecursionError)


def test_brackets_inside_strings_do_not_count_as_nesting(tmp_path):
    line = LINE.replace('"stage": "t"', '"stage": "t", "note": "' + "[{" * 50 + '\\"]"')
    r = _diff(tmp_path, line)
    assert r.exit_code == 0, r.output


@pytest.mark.parametrize("line, message", [
    (LINE.replace("1.0}", "1.0, \"x\": " + "1" * 5000 + "}"), "an integer of 5,000 digits"),
    (LINE.replace("[1, 2]", "[1" + "0" * 30 + ", 2]"), "an integer of 31 digits"),
    (LINE.replace('"0x3c00"', '"0x' + "f" * 100 + '"'), "'hex' must be a string like"),
    (LINE.replace('"0x3c00"', "15360"), "'hex' must be a string like"),
    (LINE.replace("1.0}", '"' + "9" * 100 + '"}'), "'dec' is a string of 100 characters"),
    (LINE.replace("[1, 2]", "[-1, 2]"), "'pixel' must be [x, y] non-negative integers"),
    (LINE.replace('"t"', '"' + "s" * 300 + '"'), "'stage' must be a name of 1 to 200 characters"),
    (LINE.replace('"shape": 0', '"shape": [0]'), "'shape' must be an integer or null"),
    (LINE.replace('"shape": 0', '"frame": -1'), "'frame' must be a non-negative integer"),
    ("[1, 2]\n", "must be a JSON object"),
    ('{"pixel": [1, 2]\n', "b.jsonl:1:17: not JSON"),
])
def test_malformed_values_exit_2_naming_file_and_line(tmp_path, line, message):
    r = _diff(tmp_path, line)
    assert r.exit_code == 2 and message in r.output and "b.jsonl:1" in r.output, r.output
    assert "Traceback" not in r.output


def test_huge_floats_and_non_finite_values_compare(tmp_path):
    line = LINE.replace("1.0}", "1e999}")
    assert _diff(tmp_path, line, line.replace("1e999", '"inf"')).exit_code == 0
    assert _diff(tmp_path, line, line.replace("1e999", "-1e999")).exit_code == 1


def test_files_over_the_limit_and_endless_streams_are_refused(tmp_path):
    big = tmp_path / "big.jsonl"
    with open(big, "wb") as fh:
        fh.truncate(MAX_TRACE + 1)  # sparse: nothing is read
    r = CliRunner().invoke(main, ["trace-diff", str(big), str(big)])
    assert r.exit_code == 2 and f"the limit is {MAX_TRACE:,} bytes" in r.output
    r = CliRunner().invoke(main, ["trace-diff", "/dev/zero", str(big)])
    assert r.exit_code == 2 and "larger than the limit" in r.output


def test_lines_split_only_at_newlines(tmp_path):
    line = LINE.replace('"t"', '"t\u2028u"')  # a raw U+2028 is valid inside a JSON string
    assert _diff(tmp_path, line, line).exit_code == 0
