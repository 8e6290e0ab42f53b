"""rend3r trace-diff: first divergence, order tolerance, exit codes, clean errors."""

import json

from click.testing import CliRunner

from rend3r.cli import main


def _write(path, records):
    path.write_text("".join(json.dumps(r) + "\n" for r in records))
    return str(path)


BASE = [
    {"pixel": [252, 188], "shape": 0, "stage": "a2", "hex": "0x4009", "dec": 2.017578125},
    {"pixel": [252, 188], "shape": 0, "stage": "b", "hex": "0xc400", "dec": -4.0},
    {"pixel": [252, 188], "shape": None, "stage": "cos", "hex": "0x2e22", "dec": 0.09661865234375},
]


def test_equal_traces_exit_0_even_with_other_field_order(tmp_path):
    a = _write(tmp_path / "a.jsonl", BASE)
    reordered = [dict(reversed(list(r.items()))) for r in BASE]
    b = _write(tmp_path / "b.jsonl", [reordered[2], reordered[0], reordered[1]])
    res = CliRunner().invoke(main, ["trace-diff", a, b])
    assert res.exit_code == 0, res.output
    assert "agree: 3 values" in res.output


def test_first_divergence_names_stage_pixel_shape(tmp_path):
    a = _write(tmp_path / "a.jsonl", BASE)
    changed = [dict(r) for r in BASE]
    changed[1]["hex"], changed[1]["dec"] = "0xC401", -4.00390625
    changed[2]["hex"] = "0x2e23"
    b = _write(tmp_path / "b.jsonl", changed)
    res = CliRunner().invoke(main, ["trace-diff", a, b])
    assert res.exit_code == 1
    assert "frame 0 pixel (252,188) shape 0 stage b" in res.output and "0xc400" in res.output and "0xc401" in res.output


def test_decimal_mismatch_with_equal_bits_is_a_divergence(tmp_path):
    a = _write(tmp_path / "a.jsonl", BASE)
    changed = [dict(r) for r in BASE]
    changed[0]["dec"] = 2.0
    res = CliRunner().invoke(main, ["trace-diff", a, _write(tmp_path / "b.jsonl", changed)])
    assert res.exit_code == 1 and "stage a2" in res.output


def test_missing_and_extra_records_diverge(tmp_path):
    a = _write(tmp_path / "a.jsonl", BASE)
    res = CliRunner().invoke(main, ["trace-diff", a, _write(tmp_path / "b.jsonl", BASE[:2])])
    assert res.exit_code == 1 and "only in A" in res.output and "stage cos" in res.output
    res = CliRunner().invoke(main, ["trace-diff", _write(tmp_path / "c.jsonl", BASE[:2]), a])
    assert res.exit_code == 1 and "only in B" in res.output


def test_nan_values_compare_by_bits(tmp_path):
    rec = [{"pixel": [0, 0], "shape": 1, "stage": "disc", "hex": "0x7e00", "dec": "nan"}]
    a = _write(tmp_path / "a.jsonl", rec)
    assert CliRunner().invoke(main, ["trace-diff", a, a]).exit_code == 0


def test_malformed_lines_are_clean_errors(tmp_path):
    a = _write(tmp_path / "a.jsonl", BASE)
    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"pixel": [1, 2], "stage": "b", "hex": "zz", "dec": 1}\n')
    res = CliRunner().invoke(main, ["trace-diff", a, str(bad)])
    assert res.exit_code == 2 and "bad.jsonl:1" in res.output and "Traceback" not in res.output
    res = CliRunner().invoke(main, ["trace-diff", a, str(tmp_path / "missing.jsonl")])
    assert res.exit_code == 2 and "cannot read" in res.output
