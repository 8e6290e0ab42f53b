"""A pixel's history from the trace tables against the plain rule over emulate's records."""

from pathlib import Path

import numpy as np
import pytest

from rend3r.emu.arith import make_arith
from rend3r.emu.loader import load_program
from rend3r.emu.processor import execute
from rend3r.emu.trace import SHAPE_STAGES, Trace, trace_raytrace
from rend3r.view import frames as fr
from rend3r.view.params import emu_options

ROOT = Path(__file__).resolve().parents[2]
STRESS = load_program(ROOT / "programs" / "stress4096.asm").words


def _records(options, x, y) -> list[dict]:
    out: list[dict] = []
    execute(STRESS, options, 1, lambda scene, n: trace_raytrace(scene, options, n, [(x, y)], out.append))
    return out


def _oracle(options, x, y) -> tuple[list[dict], int | None]:
    """The listed records (six fields, fp64 beside, diverges) and the first divergence, by
    the rule of docs/view.md applied record by record."""
    work, ref = _records(options, x, y), _records(fr.reference(options), x, y)

    def keyed(records):
        seen: dict = {}
        for r in records:
            k = (r["shape"], r["stage"])
            seen[k] = seen.get(k, -1) + 1
            yield (*k, seen[k]), r

    theirs = dict(keyed(ref))
    rows = []
    for key, r in keyed(work):
        f = theirs.get(key)
        if f is None:
            agrees = False
        elif isinstance(r["dec"], int):
            agrees = r["dec"] == f["dec"]
        else:
            mine, rounded = float(r["dec"]), float(options.arith.round(np.float64(float(f["dec"]))))
            agrees = mine == rounded or (np.isnan(mine) and np.isnan(rounded))
        rows.append({**r, "fp64": None if f is None else {"hex": f["hex"], "dec": f["dec"]}, "diverges": not agrees})
    first = next((i for i, r in enumerate(rows) if r["diverges"]), None)
    split = next(i for i, r in enumerate(work) if r["stage"] == "nearest")
    keep = {r["shape"] for r in work + ref if r["stage"] == "hit" and r["dec"] == 1}
    keep |= {r["dec"] for r in work + ref if r["stage"] == "nearest"}
    keep |= {rows[first]["shape"]} if first is not None and first < split else set()
    shown = [r for i, r in enumerate(rows) if i >= split or r["shape"] in keep]
    return shown, None if first is None else shown.index(rows[first])


@pytest.mark.parametrize("precision, x, y", [("fp16", 32, 24), ("bf16", 32, 24), ("e5m4", 20, 30)])
def test_a_large_scenes_history_is_the_rule_over_emulates_records(precision, x, y):
    options = emu_options({"size": [b"64x48"], "precision": [precision.encode()]}, "raytrace")
    h = fr.history(STRESS, options, 0, x, y, False)
    records, first = _oracle(options, x, y)
    assert h["shapes"] == 4096 and 0 < h["shapes_shown"] < 4096
    assert h["records"] == records and h["first_divergence"] == first


def test_table_rows_pair_by_shape_and_an_unpaired_row_diverges():
    ar = make_arith("fp16")
    values = np.arange(3 * len(SHAPE_STAGES), dtype=np.float64).reshape(3, -1)
    work = Trace(ar, 0, (0, 0), np.array([4, 7, 9]), values, [])
    theirs = values[[2, 0]] * (1 + 1e-6)  # rounds to the same fp16 values
    hit = SHAPE_STAGES.index("hit")
    theirs[:, hit] = [values[2, hit], values[0, hit] + 1]  # integers compare exactly
    pos, agree = fr._table_agreement(ar, work, Trace(ar, 0, (0, 0), np.array([9, 4]), theirs, []))
    assert pos.tolist() == [1, -1, 0]
    assert agree[2].all() and not agree[1].any()
    assert np.flatnonzero(~agree[0]).tolist() == [hit]
