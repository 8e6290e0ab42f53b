"""``rend3r emulate``: run a program and write its frames as images."""

from __future__ import annotations

import io
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

import click

from ..cliutil import JOBS, MAX_MEMORY, PRECISION, SIZE, STAGE_PRECISION
from ..progress import Progress, quiet_option
from ..errors import Rend3rError

_EPILOG = """\b
Examples:
  rend3r emulate programs/sphere.asm -o sphere.png
  rend3r emulate programs/animation.asm --frames 24 -o out/frame_{n:03}.png --gif anim.gif
  rend3r emulate sphere.mem -o s.png --precision fp32 --size 256x192 --depth-image d.png --stats
  rend3r emulate programs/shadow.asm -o bf16.png --precision bf16 --subnormals ieee
  rend3r emulate programs/stress4096.asm -o s.png --jobs 1
  rend3r emulate programs/tri_cube.asm -o cube.png --depth painter
  rend3r emulate programs/sphere.asm -o board.png --profile rend3r-2022 --trace-pixel 252,188 --trace t.jsonl
"""


def _colour(ctx, param, value: str) -> int:
    try:
        c = int(value.replace("_", ""), 0)
    except ValueError:
        raise click.BadParameter(f"expected an RGB565 value such as 0x001F, not {value!r}") from None
    if not 0 <= c <= 0xFFFF:
        raise click.BadParameter(f"RGB565 colours are 16 bits, {value!r} is not")
    return c


def _pattern(ctx, param, value: str | None) -> str | None:
    from .image import check_pattern

    if value is not None:
        try:
            check_pattern(value)
        except ValueError as exc:
            raise click.BadParameter(str(exc)) from None
    return value


@click.command("emulate", epilog=_EPILOG)
@click.argument("program", type=click.Path(dir_okay=False))
@click.option("-o", "--output", callback=_pattern, metavar="PATTERN",
              help="PNG per frame: a file name, or a pattern like out/frame_{n:03}.png for several (missing folders "
              "are made). Only {n} may appear in braces, with at most a zero-padded width; write a literal brace "
              "as {{ or }}.")
@click.option("--frames", type=click.IntRange(min=1), metavar="N", help="Render at most N frames (required for programs that loop with lr).")
@click.option("--mode", type=click.Choice(["raytrace", "raster", "hybrid"]), help="How SE/SD data is read (default: from the source's sp/tr, else raytrace); hybrid: shapes and triangles in one frame (docs/isa-extensions.md).")
@PRECISION
@STAGE_PRECISION
@click.option("--subnormals", type=click.Choice(["ftz", "ieee"]), default="ftz", show_default=True, help="Subnormals of fp16 and the other narrow formats: flush to zero (the device's IP) or IEEE gradual underflow.")
@click.option("--size", type=SIZE, default="512x384", show_default=True, help="Image size WxH (1..8192 each).")
@click.option("--background", default="0x0000", show_default=True, callback=_colour, metavar="RGB565", help="RGB565 colour where no shape is hit.")
@click.option("--depth", "visibility", type=click.Choice(["zbuffer", "painter"]), default="zbuffer", show_default=True,
              help="Raster visibility: a depth buffer, or the paper's painter order by centroid distance.")
@click.option("--depth-image", "depth_path", callback=_pattern, metavar="PATTERN", help="Depth image per frame: .npy (float32 distances) or 16-bit PNG.")
@click.option("--provenance", "prov_path", callback=_pattern, metavar="PATTERN", help="Which shape made each pixel: .npy (int32, -1 none) or PNG.")
@click.option("--gif", "gif_path", metavar="FILE", help="All frames as an animated GIF.")
@click.option("--apng", "apng_path", metavar="FILE", help="All frames as an animated PNG (lossless; .png or .apng).")
@click.option("--stats", "show_stats", is_flag=True, help="Print counters, times and the paper's device estimate.")
@click.option("--profile", type=click.Choice(["rend3r-2022"]), help="Model the original board: every device quirk (docs/device-profile.md).")
@click.option("--device-quirk", "quirks", multiple=True, metavar="NAME", help="Switch on one device quirk (repeatable); names in docs/device-profile.md.")
@click.option("--trace-pixel", "trace_pixels", multiple=True, metavar="X,Y", help="Trace every float16 intermediate of this pixel (repeatable; docs/trace.md).")
@click.option("--trace", "trace_path", metavar="FILE", help="Write pixel traces (JSON lines) to FILE instead of standard output.")
@JOBS
@MAX_MEMORY
@quiet_option
def emulate_command(program, output, frames, mode, precision, stage_precision, subnormals, size, background, visibility,
                    depth_path, prov_path, gif_path, apng_path, show_stats, profile, quirks, trace_pixels,
                    trace_path, jobs, max_memory, quiet) -> None:
    """Run a REND3R PROGRAM (source or memory image) and render its frames.

    Its outputs are all or nothing: they appear only when every one of them was written;
    after an error, no file of the run remains and files it would have replaced are kept.
    """
    import numpy as np

    from ..cliutil import default_memory
    from .budget import estimate_memory
    from .image import (ANIMATION_KINDS, DATA_KINDS, FRAME_KINDS, check_output, frame_path, is_pattern,
                        save_animation, save_depth, save_png, save_provenance)
    from .loader import load_program
    from .options import EmuOptions
    from ..fileio import Outputs
    from .processor import execute
    from .quirks import apply_quirks, quirk_names
    from .run import FRAME_BYTES_PER_PIXEL, run_program
    from .trace import parse_pixel

    if gif_path and apng_path:
        raise Rend3rError("--gif and --apng are exclusive: choose one animation format")
    if not (output or gif_path or apng_path):
        raise Rend3rError("nothing to write: give -o OUT (and/or --gif/--apng)")
    try:
        pixels = [parse_pixel(p) for p in trace_pixels]
    except ValueError as exc:
        raise Rend3rError(f"--trace-pixel: {exc}") from None
    if trace_path and not pixels:
        raise Rend3rError("--trace FILE needs at least one --trace-pixel X,Y")
    animate = gif_path or apng_path
    named = ((output, FRAME_KINDS), (depth_path, DATA_KINDS), (prov_path, DATA_KINDS),
             (gif_path, ANIMATION_KINDS["gif"]), (apng_path, ANIMATION_KINDS["apng"]))
    for path, kinds in named:
        if path:
            check_output(path, kinds)  # the extension; folders are checked by reserve()
    loaded = load_program(program)
    options = EmuOptions(precision=precision, stage_precision=stage_precision or (), subnormals=subnormals, mode=mode or loaded.mode_hint or "raytrace",
                         width=size[0], height=size[1], background=background, depth=visibility, jobs=jobs)
    selected = quirk_names(profile, quirks)
    _refuse_contradictions(selected, profile, quirks, subnormals=subnormals, visibility=visibility)
    options = apply_quirks(options, selected)
    for x, y in pixels:
        if not (0 <= x < options.width and 0 <= y < options.height):
            raise Rend3rError(f"--trace-pixel {x},{y} is outside the {options.width}x{options.height} frame")
    if pixels and options.mode == "hybrid":
        raise Rend3rError("--trace-pixel traces raytrace or raster mode; hybrid frames have no trace (docs/trace.md)")
    with _naming(program):
        count = execute(loaded.words, options, frames).frames
    if count == 0:
        raise Rend3rError(f"{program}: the program renders no frame (no nf is executed)")
    for opt, path in (("-o", output), ("--depth-image", depth_path), ("--provenance", prov_path)):
        if path and count > 1 and not is_pattern(path):
            raise Rend3rError(f"the program renders {count} frames: {opt} needs a pattern such as out/frame_{{n:03}}.png")
    budget = max_memory or default_memory()
    need, parts = estimate_memory(options.mode, options.width, options.height, count,
                                  [p for p in (output, depth_path, prov_path) if p], animate)
    if need > budget:
        raise Rend3rError(f"a {options.width}x{options.height} {options.mode} run with these outputs needs about "
                          f"{need / 2**30:.2f} GiB ({parts}); the memory budget is {budget / 2**30:.2f} GiB "
                          f"(--max-memory): render fewer pixels or frames, or raise the budget")
    outputs = Outputs()
    for path in (output, depth_path, prov_path):
        if path:
            for n in range(count) if is_pattern(path) else (0,):
                outputs.reserve(frame_path(path, n))
    for path in (animate, trace_path):
        if path:
            outputs.reserve(path)
    rgb_frames = []

    def on_frame(frame) -> None:
        if output:
            save_png(frame.rgb565, frame_path(output, frame.number), sink=outputs.write)
        if depth_path:
            save_depth(frame.depth, frame_path(depth_path, frame.number), sink=outputs.write)
        if prov_path:
            save_provenance(frame.provenance, frame_path(prov_path, frame.number), sink=outputs.write)
        if animate:
            rgb_frames.append(frame.rgb565)

    done = [0]  # thousandths of a frame

    def progress(number: int, fraction: float) -> None:
        units = int((number + fraction) * 1000)
        bar.advance(units - done[0])
        done[0] = units

    trace_buf = io.StringIO()
    on_scene = None
    if pixels:
        from .trace import jsonl_sink, trace_raster, trace_raytrace

        sink = jsonl_sink(trace_buf)
        tracer = trace_raster if options.mode == "raster" else trace_raytrace

        def on_scene(scene, number: int) -> None:
            tracer(scene, options, number, pixels, sink)

    # Extreme values (inf, NaN, 65504, huge cameras) are the renderer's documented input: their
    # rays count as misses and are reported below, so numpy's own warnings are not shown.
    with outputs, np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        with Progress(count * 1000, "rendering", quiet=quiet) as bar:
            result = run_program(loaded.words, options, frames, on_frame, progress, keep_frames=False,
                                 on_scene=on_scene, memory=budget - need + FRAME_BYTES_PER_PIXEL * options.pixels)
        if trace_path:
            outputs.write(trace_path, trace_buf.getvalue().encode())
        if animate:
            save_animation(rgb_frames, animate, "gif" if gif_path else "apng", sink=outputs.write)
        outputs.commit()
    if pixels and not trace_path:
        click.echo(trace_buf.getvalue(), nl=False)
    nan = result.stats.nan_rays
    if nan:
        click.echo(f"rend3r: warning: {nan} rays met NaN or infinity and were counted as misses "
                   f"({int(result.stats.total('nan_tests'))} of the shape tests performed; culling skips tests "
                   f"that cannot change a pixel, overflowing ones included); see --stats", err=True)
    if show_stats:
        click.echo(result.stats.report())
        if options.mode != "raster":  # the rasterizer is numpy; the raytracer's kernels come in builds
            from . import native

            click.echo(f"kernels: the {native.isa()} build (REND3R_ISA=base or avx2 caps it)")


@contextmanager
def _naming(program: str) -> Iterator[None]:
    """Put the program's file name in front of an error the processor reports (it knows
    addresses, not files), so every error names the file it is about. The processor's
    control-flow errors all come from :func:`execute`, before any rendering."""
    try:
        yield
    except Rend3rError as exc:
        message = str(exc)
        if exc.preformatted or message.startswith(f"{program}:"):
            raise
        raise Rend3rError(f"{program}: {message}", exc.exit_code) from None


#: emulate's options that a device quirk can set: click parameter -> (EmuOptions field, option name).
_QUIRK_FIELDS = {"subnormals": ("subnormals", "--subnormals"), "visibility": ("depth", "--depth")}


def _refuse_contradictions(selected: list[str], profile: str | None, quirks: tuple[str, ...], **values: object) -> None:
    """A usage error (exit 2) when an option given on the command line contradicts a selected quirk."""
    from click.core import ParameterSource

    from .quirks import contradictions

    ctx = click.get_current_context()
    given = {_QUIRK_FIELDS[p][0]: v for p, v in values.items()
             if ctx.get_parameter_source(p) not in (ParameterSource.DEFAULT, ParameterSource.DEFAULT_MAP)}
    options = {field: option for field, option in _QUIRK_FIELDS.values()}
    for field, quirk, value in contradictions(given, selected):
        source = f"--device-quirk {quirk}" if quirk in quirks else f"--profile {profile} (quirk {quirk})"
        raise click.UsageError(f"{options[field]} {given[field]} contradicts {source}, which sets {field} to "
                               f"{value}: drop one of the two (docs/device-profile.md)")

