"""Choosing the kernels' build: REND3R_ISA and native.choose (the builds' frames are
compared in test_engine_vs_reference.py)."""

from __future__ import annotations

import pytest

from rend3r.emu import native
from rend3r.emu.options import EmuOptions
from rend3r.errors import Rend3rError


@pytest.fixture
def fresh_choice():
    """isa() as a new process makes it (its pick is cached per process)."""
    native.choose(None)
    native._best.cache_clear()
    yield
    native.choose(None)
    native._best.cache_clear()


def test_the_default_is_the_last_build_the_processor_runs(fresh_choice, monkeypatch):
    monkeypatch.delenv("REND3R_ISA", raising=False)
    got = native.isa()
    assert native.runs(got) and not any(native.runs(s) for s in native.INSTRUCTION_SETS[native.INSTRUCTION_SETS.index(got) + 1:])
    assert native.kernel("nearest", EmuOptions().arith).__name__.endswith(f"_{got}")


@pytest.mark.parametrize("wanted", native.INSTRUCTION_SETS)
def test_rend3r_isa_caps_the_build(fresh_choice, monkeypatch, wanted):
    monkeypatch.setenv("REND3R_ISA", wanted)
    got = native.isa()
    assert native.runs(got) and native.INSTRUCTION_SETS.index(got) <= native.INSTRUCTION_SETS.index(wanted)
    if native.runs(wanted):
        assert got == wanted


def test_a_build_the_processor_lacks_falls_back_and_cannot_be_chosen(fresh_choice, monkeypatch):
    monkeypatch.delenv("REND3R_ISA", raising=False)
    monkeypatch.setattr(native, "runs", lambda s: s == "base")  # a processor without AVX2
    assert native.isa() == "base"
    with pytest.raises(ValueError, match="does not run the avx512 build"):
        native.choose("avx512")


def test_an_unknown_rend3r_isa_names_the_choices(fresh_choice, monkeypatch):
    monkeypatch.setenv("REND3R_ISA", "sse9")
    with pytest.raises(Rend3rError, match="REND3R_ISA='sse9': choose one of base, avx2, avx512"):
        native.isa()


def test_a_long_rend3r_isa_is_shown_cut(fresh_choice, monkeypatch):
    monkeypatch.setenv("REND3R_ISA", "x" * 5000)
    with pytest.raises(Rend3rError, match=r"REND3R_ISA='x{40}'\.\.\. \(5,000 characters\): choose one of") as e:
        native.isa()
    assert len(str(e.value)) < 200


def test_choose_sets_the_build_until_it_is_cleared(fresh_choice):
    picked = native.isa()
    native.choose("base")
    assert native.isa() == "base" and not native.avx2()
    native.choose(None)
    assert native.isa() == picked


@pytest.mark.parametrize("name", ["sse9", "AVX2", ""])
def test_choose_refuses_a_build_it_does_not_have(fresh_choice, name):
    with pytest.raises(ValueError, match="choose one of base, avx2, avx512"):
        native.choose(name)
    assert native.isa() in native.INSTRUCTION_SETS
