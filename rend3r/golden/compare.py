"""``rend3r compare``: metrics between two images or raw RGB565 frame buffers."""

from __future__ import annotations

import math
from pathlib import Path

import click
import numpy as np

from ..cliutil import SIZE, finite
from ..errors import Rend3rError
from .metrics import ImageMetrics, as_rgb888, diff_image, image_metrics

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
DEVICE_SIZE = (512, 384)


def load_image(path: Path, size: tuple[int, int] | None = None) -> np.ndarray:
    """Read a PNG (any mode, as RGB888) or a raw little-endian RGB565 frame buffer.

    A raw buffer needs ``size`` unless its length is that of the device's 512x384 frame.
    """
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise Rend3rError(f"cannot read {path}: {exc.strerror or exc}") from None
    if data.startswith(PNG_MAGIC):
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(path) as im:
                return np.asarray(im.convert("RGB"), dtype=np.uint8)
        except (OSError, ValueError, SyntaxError, UnidentifiedImageError, Image.DecompressionBombError) as exc:
            raise Rend3rError(f"cannot read PNG {path}: {exc}") from None
    w, h = size if size is not None else DEVICE_SIZE
    if len(data) != 2 * w * h:
        hint = "" if size is not None else " (pass --size WxH for raw frame buffers of other sizes)"
        raise Rend3rError(
            f"{path}: {len(data)} bytes is not a PNG nor a {w}x{h} RGB565 frame buffer ({2 * w * h} bytes){hint}"
        )
    return np.frombuffer(data, dtype="<u2").reshape(h, w).astype(np.uint16)


def save_rgb888_png(rgb: np.ndarray, path: Path) -> None:
    """Write an (H, W, 3) uint8 image as PNG, atomically (missing folders are made)."""
    from PIL import Image

    from ..emu.image import write_image
    from ..fileio import write_atomic

    write_image(path, Image.fromarray(np.ascontiguousarray(rgb), mode="RGB"), sink=write_atomic)


def compare_files(
    a: Path, b: Path, diff: Path | None = None, size: tuple[int, int] | None = None
) -> ImageMetrics:
    """Metrics of ``b`` against reference ``a``; writes the diff picture when asked."""
    if diff is not None:
        from ..emu.image import check_output
        from ..fileio import check_writable

        check_output(diff, (".png",))
        check_writable(diff)
    x = as_rgb888(load_image(a, size))
    y = as_rgb888(load_image(b, size))
    if x.shape != y.shape:
        raise Rend3rError(f"image sizes differ: {a} is {x.shape[1]}x{x.shape[0]}, {b} is {y.shape[1]}x{y.shape[0]}")
    if diff is not None:
        save_rgb888_png(diff_image(x, y), diff)
    return image_metrics(x, y)


def _psnr(ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
    if value is not None and math.isnan(value):
        raise click.BadParameter("must be a number of dB, not nan")
    return value


@click.command("compare")
@click.argument("a", type=click.Path(path_type=Path, dir_okay=False))
@click.argument("b", type=click.Path(path_type=Path, dir_okay=False))
@click.option("-o", "--output", "diff_path", type=click.Path(path_type=Path), metavar="FILE",
              help="Write a diff PNG (changed pixels magenta); missing folders are made.")
@click.option("--diff", "old_diff_path", type=click.Path(path_type=Path), hidden=True)  # -o's older spelling
@click.option("--max-channel", type=click.IntRange(0, 255), default=0, show_default=True, metavar="N", help="Largest allowed channel difference (RGB888).")
@click.option("--max-share", type=float, callback=finite(0.0, 1.0), default=None, metavar="SHARE", help="Largest allowed share of differing pixels (0..1).")
@click.option("--min-psnr", type=float, default=None, callback=_psnr, metavar="DB", help="Smallest allowed PSNR in dB (inf: identical).")
@click.option("--size", type=SIZE, default=None, help="Size of raw RGB565 inputs (default 512x384).")
def compare_command(
    a: Path, b: Path, diff_path: Path | None, old_diff_path: Path | None, max_channel: int, max_share: float | None,
    min_psnr: float | None, size: tuple[int, int] | None
) -> None:
    """Compare image B against reference A and print the metrics.

    A and B are PNGs or raw little-endian RGB565 frame buffers. Exit status, as cmp and
    diff: 0 when B is within every given tolerance (by default: identical), 1 when it is
    not, 2 on trouble (a missing or unreadable file, sizes that differ, a bad option).

    \b
    Example:
      rend3r compare programs/golden/sphere.png out/sphere.png --max-channel 8 -o out/diff.png
    """
    if diff_path is not None and old_diff_path is not None:
        raise click.UsageError("-o and --diff name the same output: give one")
    diff_path = diff_path or old_diff_path
    try:
        m = compare_files(a, b, diff_path, size)
    except Rend3rError as exc:
        raise Rend3rError(str(exc), exit_code=2) from None
    ok = m.within(max_channel, max_share, min_psnr)
    click.echo(m.describe())
    if diff_path is not None:
        click.echo(f"diff written to {diff_path}")
    click.echo("within tolerance" if ok else "NOT within tolerance")
    click.get_current_context().exit(0 if ok else 1)
