"""The explore campaign's tasks: designs of one program batched, big programs alone and first."""

from __future__ import annotations

from rend3r.explore.campaign import BATCH, BATCH_WORK, ProgramSpec, batches


def _spec(name: str, words: int, frames: int = 1) -> ProgramSpec:
    return ProgramSpec(name, tuple(range(words)), "raytrace", frames)


def test_every_pair_lands_in_exactly_one_task_in_design_order():
    specs = [_spec("small", 30), _spec("anim", 55, 8), _spec("big", 40_000)]
    designs = [f"e5m{m}" for m in range(1, 11)]
    pairs = [(s, d) for d in designs for s in specs]
    tasks = batches(pairs, 256 * 192)
    flat = [(s.name, d) for s, ds in tasks for d in ds]
    assert sorted(flat) == sorted((s.name, d) for s, d in pairs)
    for spec in specs:
        assert [d for s, ds in tasks if s is spec for d in ds] == designs


def test_small_programs_batch_big_ones_run_alone_and_first():
    small, big = _spec("small", 30), _spec("big", 40_000)
    tasks = batches([(s, f"e6m{m}") for s in (small, big) for m in range(1, 9)], 256 * 192)
    assert [len(ds) for s, ds in tasks if s is small] == [BATCH, 8 - BATCH]
    assert [len(ds) for s, ds in tasks if s is big] == [1] * 8
    assert all(s is big for s, _ in tasks[:8])  # the long renders start first
    assert 30 * 256 * 192 * BATCH <= BATCH_WORK  # the small program's batch is within the bound
