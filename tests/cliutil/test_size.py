"""The shared WxH size parser and click type."""

import click
import pytest
from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st

from rend3r.cliutil import MAX_SIDE, SIZE, parse_size


@given(st.integers(1, MAX_SIDE), st.integers(1, MAX_SIDE), st.sampled_from(["x", "X", " x "]))
def test_valid_sizes_round_trip(w, h, sep):
    assert parse_size(f"{w}{sep}{h}") == (w, h)


@pytest.mark.parametrize("text", ["", "512", "512x", "x384", "0x5", "5x0", "-1x5", "8193x1", "1x100000",
                                  "1.5x2", "axb", "1x2x3", "١٢x3"])
def test_bad_sizes_are_value_errors(text):
    with pytest.raises(ValueError):
        parse_size(text)


def test_device_cap():
    assert parse_size("64x64", max_side=64) == (64, 64)
    with pytest.raises(ValueError, match="1..64"):
        parse_size("65x1", max_side=64)


def test_click_type_exits_2_with_the_reason():
    @click.command()
    @click.option("--size", type=SIZE, default="4x3")
    def cmd(size):
        click.echo(repr(size))

    assert CliRunner().invoke(cmd, []).output.strip() == "(4, 3)"
    r = CliRunner().invoke(cmd, ["--size", "100000x100000"])
    assert r.exit_code == 2 and "1..8192" in r.output


def test_click_type_with_a_smaller_cap_and_the_wxh_metavar():
    from rend3r.cliutil import SizeType

    @click.command()
    @click.option("--size", type=SizeType(64), default="64x48", show_default=True)
    def cmd(size):
        click.echo(repr(size))

    assert "--size WxH" in CliRunner().invoke(cmd, ["--help"]).output
    assert CliRunner().invoke(cmd, ["--size", "64x64"]).output.strip() == "(64, 64)"
    r = CliRunner().invoke(cmd, ["--size", "65x1"])
    assert r.exit_code == 2 and "1..64" in r.output
