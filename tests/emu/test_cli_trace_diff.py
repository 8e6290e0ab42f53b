"""trace-diff on files that are not traces: exit 2 (trouble), never a traceback."""

import json

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


NAN = LINE.replace('"0x3c00", "dec": 1.0', '"0xfe00", "dec": "nan"')


@pytest.mark.parametrize("other, any_code, exact_code", [
    (NAN, 0, 0),  # the same NaN
    (NAN.replace("0xfe00", "0x7e00"), 0, 1),  # SoftFloat's default NaN
    (NAN.replace("0xfe00", "0x7c01"), 0, 1),  # a signalling payload
    (LINE.replace("0x3c00", "0x7c00").replace("1.0}", '"inf"}'), 1, 1),  # infinity is not a NaN
    (LINE, 1, 1),
])
def test_nans_are_equal_unless_nan_bits_exact(tmp_path, other, any_code, exact_code):
    a = tmp_path / "a.jsonl"
    a.write_text(NAN)
    b = tmp_path / "b.jsonl"
    b.write_text(other)
    default = CliRunner().invoke(main, ["trace-diff", str(a), str(b)])
    assert default.exit_code == any_code, default.output
    assert CliRunner().invoke(main, ["trace-diff", str(a), str(b), "--nan-bits", "any"]).exit_code == any_code
    exact = CliRunner().invoke(main, ["trace-diff", str(a), str(b), "--nan-bits", "exact"])
    assert exact.exit_code == exact_code, exact.output
    if exact_code:
        assert "first divergence" in exact.output


# --- hypothesis: mutated real traces, deep nesting, huge numbers, wrong types (fixed budget) ---

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from .scenes import ONE_SPHERE  # noqa: E402

SCENE = ONE_SPHERE + "er\n"  # two er: the end the device needs


@pytest.fixture(scope="module")
def real_trace(tmp_path_factory):
    d = tmp_path_factory.mktemp("trace")
    (d / "s.asm").write_text(SCENE)
    r = CliRunner().invoke(main, ["emulate", str(d / "s.asm"), "-o", str(d / "f.png"), "--size", "16x12",
                                  "--trace-pixel", "8,6", "--trace-pixel", "0,0", "--trace", str(d / "t.jsonl")])
    assert r.exit_code == 0, r.output
    return (d / "t.jsonl").read_text()


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-10**30, 10**30) | st.floats(allow_nan=True) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3),
    max_leaves=8)
FIELDS = ("frame", "pixel", "shape", "stage", "hex", "dec")


def _mutate(text: str, data) -> str:
    lines = text.splitlines()
    i = data.draw(st.integers(0, len(lines) - 1))
    kind = data.draw(st.sampled_from(["chars", "field", "nest", "number", "splice"]))
    if kind == "chars":
        line = lines[i]
        at = data.draw(st.integers(0, len(line)))
        cut = data.draw(st.integers(0, 4))
        lines[i] = line[:at] + data.draw(st.text(max_size=6)) + line[at + cut:]
    elif kind == "field":
        record = json.loads(lines[i])
        key = data.draw(st.sampled_from(FIELDS))
        if data.draw(st.booleans()):
            record.pop(key, None)
        else:
            record[key] = data.draw(JSON_VALUES)
        lines[i] = json.dumps(record)
    elif kind == "nest":
        depth = data.draw(st.integers(1, 5000))
        lines[i] = lines[i].replace('"dec": ', '"dec": ' + "[" * depth, 1) + "]" * data.draw(st.integers(0, depth))
    elif kind == "number":
        digits = data.draw(st.integers(1, 6000))
        big = data.draw(st.sampled_from(["1" * digits, "1e" + "9" * min(digits, 30), "-" + "9" * digits + ".5"]))
        key = data.draw(st.sampled_from(["dec", "frame", "shape"]))
        record = json.loads(lines[i])
        record[key] = 0
        lines[i] = json.dumps(record).replace(f'"{key}": 0', f'"{key}": {big}')
    else:
        lines.insert(i, lines[data.draw(st.integers(0, len(lines) - 1))][: data.draw(st.integers(0, 40))])
    return "\n".join(lines) + "\n"


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_fuzz_mutated_traces_exit_0_1_or_2_with_a_message(tmp_path, real_trace, data):
    mutated = _mutate(real_trace, data)
    a, b = tmp_path / "a.jsonl", tmp_path / "b.jsonl"
    a.write_text(real_trace)
    b.write_text(mutated, encoding="utf-8", errors="surrogatepass")
    for first, second in ((a, b), (b, a)):
        r = CliRunner().invoke(main, ["trace-diff", str(first), str(second)])
        assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
        assert r.exit_code in (0, 1, 2)
        if r.exit_code == 2:
            assert "rend3r: error: " in r.output and "b.jsonl:" in r.output, r.output
        elif r.exit_code == 1:
            assert r.output.startswith("first divergence: ")
