"""Float options refuse NaN and infinities (click's FloatRange lets NaN through)."""

from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.cli import main

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e400"])
@pytest.mark.parametrize("args", [
    ["explore", "{root}/programs/sphere.asm", "-o", "{tmp}/x", "--search", "--min-psnr"],
    ["compare", "{root}/programs/golden/sphere.png", "{root}/programs/golden/sphere.png", "--max-share"],
    ["device", "--serial", "loop://", "-o", "{tmp}/d", "--max-frame-rate"],
    ["svo", "render", "{tmp}/x.svo", "-o", "{tmp}/x.png", "--distance"],
])
def test_a_float_option_refuses_what_is_not_finite(args, value, tmp_path):
    result = CliRunner().invoke(main, [a.format(tmp=tmp_path, root=ROOT) for a in args] + [value])
    assert result.exit_code == 2, result.output
    assert "is not in the range" in result.output
    assert not list(tmp_path.iterdir())
