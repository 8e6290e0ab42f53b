"""A frame's stats do not depend on the thread count: the bands a frame is split into (and
so what each band's bounds let its rays skip, which the test counts show) depend on the
frame, never on --jobs."""

from __future__ import annotations

from dataclasses import replace

from hypothesis import given, settings

from rend3r.emu.options import EmuOptions
from rend3r.emu.raytracer import render_frame

from .test_engine_vs_reference import assert_same, program, scene_args, scene_of


@settings(max_examples=150, derandomize=True, deadline=None)
@given(*scene_args)
def test_counts_are_the_same_on_one_thread_and_four(cam, lights, shapes, ties, prec):
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=256, height=192)  # three bands when lit
    scene = scene_of(program(cam, lights, shapes, ties, options), options)
    counts = [render_frame(scene, replace(options, jobs=jobs))[1] for jobs in (1, 4)]
    one, four = ((c.tests, c.skipped, c.nan_tests, c.hits, c.shadow_rays, c.nan_rays) for c in counts)
    assert one == four


@settings(max_examples=40, derandomize=True, deadline=None)
@given(*scene_args)
def test_frames_and_counts_the_same_on_any_split_of_an_odd_frame(cam, lights, shapes, ties, prec):
    """An odd width and height, so that no pass's parts (csrc/band.c taper: shrinking
    parts) start on whole packets or rows alike from one thread count to another."""
    options = EmuOptions(precision=prec[0], subnormals=prec[1], width=257, height=131)
    scene = scene_of(program(cam, lights, shapes, ties, options), options)
    runs = [render_frame(scene, replace(options, jobs=jobs)) for jobs in (1, 2, 3)]
    (first, counts), rest = runs[0], runs[1:]
    for frame, other in rest:
        assert_same(first, frame)
        assert replace(other, seconds=0) == replace(counts, seconds=0)
