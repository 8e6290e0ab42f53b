"""``rend3r svo``: build octrees from meshes, render them, sweep hardware design points.

Every command checks its outputs before any work, shows progress on a terminal
(:mod:`rend3r.progress`, ``-q`` for none), and stops on Ctrl-C within a fraction of a
second with nothing written (:mod:`rend3r.svo.interrupt`).
"""

from __future__ import annotations

import json
import time
from functools import partial
from pathlib import Path

import click

from ..campaign.options import SCHEDULER
from ..cliutil import SIZE, finite
from ..errors import Rend3rError
from ..fileio import Outputs
from ..progress import Progress, quiet_option

_EPILOG = """\b
Examples:
  rend3r svo model folded -o out/folded.ply
  rend3r svo build out/folded.ply -o out/folded.svo --depth 10
  rend3r svo render out/folded.svo -o out/folded.png --cost out/cost.png --stats
  rend3r svo render out/folded.svo -o out/hybrid.png --with-program programs/sphere.asm --place 0.8,0.3,-3.5,0.8
  rend3r svo sweep out/folded.svo -o out/sweep
"""


@click.group("svo", epilog=_EPILOG)
@click.pass_context
def svo_group(ctx: click.Context) -> None:
    """Sparse voxel octrees after the SVO thesis: build, trace, simulate."""
    import numpy as np

    # every overflow or invalid operation is checked where it matters (non-finite rays,
    # coordinates, bounds) and reported as an error; numpy's own warnings stay quiet
    ctx.with_resource(np.errstate(all="ignore"))


def _commit(out: Outputs, summary: str, quiet: bool) -> None:
    """Move the staged outputs into place and print the summary, with Ctrl-C ignored: from
    here on the run completes (exit 0, every output written) instead of stopping half-way."""
    from .interrupt import ctrl_c_ignored

    with ctrl_c_ignored():
        out.commit()
        if not quiet:
            click.echo(summary)


def _memory(ctx, param, value: str | None) -> int | None:
    from .budget import parse_bytes

    if value is None:
        return None
    try:
        return parse_bytes(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


@svo_group.command("model", short_help="Write a procedural mesh: sphere, torus or folded.")
@click.argument("name", type=click.Choice(["sphere", "torus", "folded"]), metavar="NAME")
@click.option("-o", "--output", required=True, metavar="FILE",
              help="Mesh file to write: .obj, .ply or .stl (missing folders are made).")
@click.option("--detail", type=click.IntRange(4, 2048), default=None, metavar="N",
              help="Tessellation: bands around the model (default: the model's own).")
@click.option("--ascii", "ascii_", is_flag=True, help="ASCII PLY/STL instead of binary.")
@quiet_option
def model_cmd(name: str, output: str, detail: int | None, ascii_: bool, quiet: bool) -> None:
    """Write the procedural mesh NAME: sphere, torus or folded (no downloads).

    \b
    Example:
      rend3r svo model torus -o out/torus.obj --detail 64
      rend3r svo model folded -o out/folded.ply
    """
    from .mesh_io import encode_mesh
    from .models import make_model

    with Outputs() as out:
        out.reserve(output)
        verts, faces = make_model(name, detail)
        out.write(output, encode_mesh(output, verts, faces, binary=not ascii_))
        _commit(out, f"{output}: {len(verts)} vertices, {len(faces)} triangles", quiet)


@svo_group.command("build", short_help="Voxelise a mesh (or read a binvox grid) into a .svo octree.")
@click.argument("mesh", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, metavar="FILE",
              help=".svo file to write (missing folders are made).")
@click.option("--depth", type=click.IntRange(1, 16), default=None, metavar="N",
              help="Octree levels, 2**N voxels per axis. Required for a mesh; a binvox "
                   "grid has its own (given, it must match).")
@click.option("--solid", is_flag=True, help="Fill the inside of closed meshes.")
@click.option("--ptr-bits", type=click.IntRange(4, 15), default=15, show_default=True, metavar="N",
              help="Relative pointer width (smaller forces far pointers).")
@click.option("--binvox", "binvox_out", default=None, metavar="FILE",
              help="Also write the voxels as a binvox file.")
@click.option("--max-memory", "max_memory", default=None, callback=_memory, metavar="SIZE",
              help="Refuse, before voxelising, a build whose estimate exceeds SIZE (e.g. 2G, 512M); "
                   "default: half the machine's physical memory.")
@quiet_option
def build_cmd(mesh: str, output: str, depth: int | None, solid: bool, ptr_bits: int,
              binvox_out: str | None, max_memory: int | None, quiet: bool) -> None:
    """Voxelise MESH (.obj .ply .stl, or a .binvox grid) and write the thesis's node format.

    Writes both outputs (the .svo and, with --binvox, the binvox file) or neither.

    \b
    Example:
      rend3r svo build out/folded.ply -o out/folded.svo --depth 10
      rend3r svo build out/torus.obj -o out/torus.svo --depth 8 --solid --binvox out/torus.binvox
      rend3r svo build out/torus.binvox -o out/torus2.svo
    """
    import numpy as np

    from .binvox import encode_binvox_codes, read_binvox_codes
    from .budget import check_budget, default_budget
    from .fileformat import SvoModel, encode_svo
    from .mesh_io import read_mesh
    from .octree import build_octree_codes
    from .voxelize import voxelize_codes

    budget = max_memory or default_budget()
    bars = partial(Progress, quiet=quiet)
    start = time.perf_counter()
    with Outputs() as out:
        for path in (output, binvox_out):
            if path:
                out.reserve(path)
        if Path(mesh).suffix.lower() == ".binvox":
            if solid:
                raise Rend3rError("--solid applies to meshes; binvox voxels are used as stored")
            codes, dim, translate, scale = read_binvox_codes(
                mesh, lambda voxels, held: check_budget((voxels, 0), budget, mesh, held))
            if len(codes) == 0:
                raise Rend3rError(f"{mesh}: the binvox grid holds no solid voxel")
            need = max((dim - 1).bit_length(), 1)
            if depth is not None and depth != need:
                raise Rend3rError(f"{mesh}: a {dim}^3 binvox grid needs --depth {need}")
            depth = need
            h = scale / dim
            lo = np.asarray(translate, dtype=np.float64)
            if not (np.all(np.isfinite(lo)) and np.isfinite(h) and h > 0
                    and np.all(np.isfinite(lo + h * (1 << depth)))):
                raise Rend3rError(f"{mesh}: binvox translate and scale must be finite, scale positive")
        else:
            if depth is None:
                raise Rend3rError(f"{mesh}: --depth is required for mesh input (e.g. --depth 8: 256 "
                                  "voxels per axis)")
            verts, faces = read_mesh(mesh)
            try:
                codes, lo, h = voxelize_codes(verts, faces, depth, solid, budget, bars)
            except Rend3rError as exc:
                raise Rend3rError(f"{mesh}: {exc}") from None
            del verts, faces
        count = len(codes)
        # the binvox bytes first: written and freed before the octree's levels are held
        if binvox_out:
            out.write(binvox_out, encode_binvox_codes(codes, depth, tuple(lo), h * (1 << depth)))
        tree = build_octree_codes(codes, depth, ptr_bits, bars)
        del codes
        hi = lo + h * (1 << depth)
        bounds = tuple(float(x) for x in lo) + tuple(float(x) for x in hi)
        out.write(output, encode_svo(SvoModel(tree, bounds, count)))
        _commit(out, f"{output}: depth {depth}, {count} voxels, {len(tree.words)} words "
                     f"({tree.far_count()} far pointers), {time.perf_counter() - start:.2f} s", quiet)


def _kernel(kernel: str, fixed: bool) -> str:
    """The traversal kernel to run; prints a note on stderr when auto falls back to numpy."""
    from .traverse import resolve_kernel

    try:
        use, note = resolve_kernel(kernel, fixed)
    except ValueError as exc:
        raise Rend3rError(str(exc)) from None
    if note:
        click.echo(f"note: {note}", err=True)
    return use


_KERNEL = click.option("--kernel", type=click.Choice(["auto", "numba", "numpy"]), default="auto",
                       show_default=True,
                       help="Traversal: compiled numba kernel (pip install 'rend3r[fast]') or numpy; "
                            "auto = numba if installed. Identical results.")

MAX_PLACE = 65504.0
"""Largest --place coordinate or half size: the largest float16, the device's scene range."""


def _place(ctx, param, value: str | None):
    """``--place X,Y,Z,S`` -> the world box (x - s, y - s, z - s, x + s, y + s, z + s)."""
    if value is None:
        return None
    try:
        x, y, z, s = (float(v) for v in value.split(","))
    except ValueError:
        raise click.BadParameter("expected X,Y,Z,HALF_SIZE") from None
    if not (all(abs(v) <= MAX_PLACE for v in (x, y, z)) and 0 < s <= MAX_PLACE):
        raise click.BadParameter(f"X, Y, Z must be finite within +-{MAX_PLACE:g} and "
                                 f"HALF_SIZE in (0, {MAX_PLACE:g}] (float16 scene range)")
    bounds = (x - s, y - s, z - s, x + s, y + s, z + s)
    if any(bounds[i] >= bounds[i + 3] for i in range(3)):
        raise click.BadParameter(f"HALF_SIZE {s:g} is too small to resolve at that position")
    return bounds


@svo_group.command("render")
@click.argument("model", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, metavar="FILE",
              help="PNG image to write (missing folders are made).")
@click.option("--size", type=SIZE, default="640x480", show_default=True, help="Image size WxH (1..8192 each).")
@click.option("--mode", type=click.Choice(["shaded", "depth"]), default="shaded", show_default=True)
@click.option("--stack", type=click.IntRange(0, 64), default=8, show_default=True, metavar="N",
              help="Short-stack depth (0 = restart only).")
@click.option("--float", "use_float", is_flag=True, help="float64 reference instead of 16.16.")
@_KERNEL
@click.option("--azimuth", type=float, default=35.0, show_default=True, callback=finite(-1e6, 1e6),
              metavar="DEG", help="Degrees around the vertical axis (-1e6..1e6).")
@click.option("--elevation", type=float, default=25.0, show_default=True, callback=finite(-89.9, 89.9),
              metavar="DEG", help="Degrees above the horizon (-89.9..89.9).")
@click.option("--distance", type=float, default=1.6, show_default=True, callback=finite(0.1, 1e6),
              metavar="D", help="Camera distance in half-diagonals of the model's cube (0.1..1e6).")
@click.option("--cost", "cost_path", default=None, metavar="FILE",
              help="Also write the per-ray cost image (PNG).")
@click.option("--stats", "show_stats", is_flag=True, help="Print traversal statistics as JSON.")
@click.option("--with-program", "program", default=None, type=click.Path(dir_okay=False), metavar="FILE",
              help="Merge into the frames of this REND3R program (its camera is used).")
@click.option("--place", default=None, callback=_place, metavar="X,Y,Z,S",
              help="With --with-program: model centre and half size.")
@quiet_option
def render_cmd(model: str, output: str, size, mode: str, stack: int, use_float: bool, kernel: str,
               azimuth: float, elevation: float, distance: float, cost_path: str | None,
               show_stats: bool, program: str | None, place: tuple[float, ...] | None,
               quiet: bool) -> None:
    """Trace MODEL.svo and write an image (depth or shaded).

    Writes every output (the image and, with --cost, the cost image) or none.

    \b
    Example:
      rend3r svo render out/folded.svo -o out/folded.png --cost out/cost.png --stats
      rend3r svo render out/folded.svo -o out/top.png --elevation 80 --mode depth
      rend3r svo render out/folded.svo -o out/hybrid.png --with-program programs/sphere.asm --place 0.8,0.3,-3.5,0.8
    """
    from PIL import Image

    from ..emu.image import check_output
    from .camera import model_matrix, orbit_camera
    from .fileformat import read_svo
    from .render import cost_image, render

    with Outputs() as out:
        for path in (output, cost_path):
            if path:
                check_output(path, (".png",))
                out.reserve(path)
        if place is not None and program is None:
            raise Rend3rError("--place needs --with-program")
        kernel = _kernel(kernel, not use_float)
        svo = read_svo(model)
        if program is not None:
            from ..emu.image import rgb565_to_rgb888
            from .hybrid import program_hybrid

            bounds = place or svo.bounds
            with Progress(size[0] * size[1], "tracing", quiet=quiet) as bar:
                frames = program_hybrid(svo, program, model_matrix(bounds), size[0], size[1], stack,
                                        kernel=kernel, on_rays=bar.advance)
            if not frames:
                raise Rend3rError(f"{program}: the program renders no frame")
            out.write(output, _png(Image.fromarray(rgb565_to_rgb888(frames[0][0]))))
            _commit(out, f"{output}: hybrid frame, {size[0]}x{size[1]}", quiet)
            return
        cam = orbit_camera(svo.bounds, azimuth, elevation, distance, size[0], size[1])
        start = time.perf_counter()
        with Progress(size[0] * size[1], "tracing", quiet=quiet) as bar:
            r = render(svo, cam, stack, not use_float, mode, kernel=kernel, on_rays=bar.advance)
        elapsed = time.perf_counter() - start
        out.write(output, _png(Image.fromarray(r.rgb)))
        if cost_path:
            out.write(cost_path, _png(Image.fromarray(cost_image(r.cost))))
        stats = r.result.stats()
        stats["seconds"] = round(elapsed, 3)
        stats["rays_per_s"] = round(stats["rays"] / max(elapsed, 1e-9))
        if show_stats:
            _commit(out, json.dumps(stats, indent=2), False)
        else:
            _commit(out, f"{output}: {stats['hits']}/{stats['rays']} hits, "
                         f"{stats['requests_per_ray']:.2f} requests/ray, {elapsed:.2f} s", quiet)


def _png(image) -> bytes:
    """A PIL image encoded as PNG bytes."""
    import io

    buf = io.BytesIO()
    image.save(buf, format="PNG")
    return buf.getvalue()


@svo_group.command("sweep", short_help="Simulate the cache/core design points of Tables 7.1 and 8.2.")
@click.argument("model", type=click.Path(dir_okay=False))
@click.option("-o", "--output", required=True, metavar="STEM",
              help="Writes STEM.csv and STEM.md (missing folders are made).")
@click.option("--size", type=SIZE, default="320x240", show_default=True, help="Image size WxH (1..8192 each).")
@click.option("--views", type=click.IntRange(1, 16), default=1, show_default=True, metavar="N",
              help="Camera azimuths averaged (the thesis used four for Table 7.1).")
@click.option("--jobs", type=click.IntRange(0, 64), default=0, show_default=True, metavar="N",
              help="Worker processes of the local cluster (--scheduler local); 0 uses one per core.")
@SCHEDULER
@_KERNEL
@quiet_option
def sweep_cmd(model: str, output: str, size, views: int, jobs: int, scheduler: str, kernel: str,
              quiet: bool) -> None:
    """Simulate the design points of the thesis's Tables 7.1 and 8.2 on MODEL.svo.

    Writes both tables (STEM.csv, STEM.md) or neither. The stack depths are traced, and the
    caches simulated, as independent tasks on --scheduler (docs/campaigns.md); the tables
    do not depend on where they ran.

    \b
    Example:
      rend3r svo sweep out/folded.svo -o out/sweep
      rend3r svo sweep out/folded.svo -o out/sweep4 --views 4 --jobs 2
      rend3r svo sweep out/folded.svo -o out/sweep --scheduler tcp://10.0.0.5:8786
    """
    from ..campaign.runner import Campaign
    from .fileformat import read_svo
    from .sweep import run_sweep, thesis_points, to_csv, to_markdown

    csv_path, md_path = output + ".csv", output + ".md"
    with Outputs() as out:
        for path in (csv_path, md_path):
            out.reserve(path)
        kernel = _kernel(kernel, True)
        svo = read_svo(model)
        start = time.perf_counter()
        with Campaign(scheduler, workers=jobs or None, processes=True) as campaign:
            rows = run_sweep(svo, thesis_points(), campaign, size[0], size[1], views,
                             partial(Progress, quiet=quiet), kernel)
        header = (f"# SVO design sweep: {Path(model).name}, {size[0]}x{size[1]}, {views} view(s)\n\n"
                  "Frame times from the model in rend3r/svo/cores.py (50 MHz, 95 MB/s).\n\n")
        out.write(csv_path, to_csv(rows).encode())
        out.write(md_path, (header + to_markdown(rows)).encode())
        _commit(out, f"{csv_path}, {md_path}: {len(rows)} design points, "
                     f"{time.perf_counter() - start:.1f} s", quiet)
