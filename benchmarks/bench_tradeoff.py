"""The speed/accuracy trade of the emulator's precisions, measured on every example program.

Renders each ``programs/*.asm`` in fp16 (ftz), fp16 (ieee), fp32 and fp64 and reports per
program and mode: median wall time per frame over ``--repeat`` runs, and the error against
fp64 (PSNR, max channel error, share of differing pixels, silhouette pixels where hit/miss
differs, pixels whose nearest shape differs). Writes ``tradeoff.md`` (table and summary)
and ``tradeoff.png`` (time against error, one point per mode and program, drawn with
Pillow) into ``--out`` (default ``docs/``): the folder is made before any measuring, and
the two files are written together or not at all.

Each program is measured by one task of a campaign (:mod:`rend3r.campaign.runner`,
``docs/campaigns.md``) on ``--scheduler``: ``none`` (the default) measures one program at a
time, so no other render shares the machine with the one being timed; ``local`` or
``tcp://HOST:PORT`` measure programs side by side (quicker, the error figures the same,
the times those of renders sharing their workers' machines).

    python benchmarks/bench_tradeoff.py [--size 256x192] [--repeat 3] [--out DIR] [--scheduler none]
"""

from __future__ import annotations

import argparse
import io
import math
import statistics
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from rend3r.campaign.runner import Campaign, parse_scheduler
from rend3r.cliutil import parse_size
from rend3r.emu import EmuOptions, load_program, run_program
from rend3r.errors import Rend3rError
from rend3r.fileio import make_output_folder, write_all
from rend3r.golden.catalog import ExampleProgram, discover
from rend3r.golden.metrics import image_metrics, provenance_metrics
from rend3r.memory import reuse_freed_memory
from rend3r.progress import Progress

ROOT = Path(__file__).resolve().parents[1]
MODES: dict[str, dict[str, str]] = {
    "fp16-ftz": {"precision": "fp16", "subnormals": "ftz"},
    "fp16-ieee": {"precision": "fp16", "subnormals": "ieee"},
    "fp32": {"precision": "fp32"},
    "fp64": {"precision": "fp64"},
}
MODE_COLOURS = {"fp16-ftz": (214, 39, 40), "fp16-ieee": (255, 127, 14), "fp32": (31, 119, 180), "fp64": (44, 160, 44)}
#: PSNR plotted for frames identical to fp64 (infinite PSNR).
PSNR_IDENTICAL = 100.0


@dataclass
class Row:
    program: str
    mode: str
    frames: int
    seconds_per_frame: float
    psnr: float
    max_channel: int
    share_differing: float
    silhouette: int
    nearest_shape: int


def render(program: ExampleProgram, words: list[int], mode_hint: str | None, options: EmuOptions):
    mode = program.mode or mode_hint or options.mode
    return run_program(words, options=replace(options, mode=mode), frames=program.frames).frames


def measure(program: ExampleProgram, words: list[int], mode_hint: str | None, size: tuple[int, int],
            repeat: int) -> list[Row] | str:
    """The campaign task: one loaded program in every mode; its rows, or why it was skipped
    (a Rend3rError, e.g. a mode the emulator lacks, must not stop the other programs)."""
    try:
        return _measure(program, words, mode_hint, size, repeat)
    except Rend3rError as exc:
        return str(exc)


def _measure(program: ExampleProgram, words: list[int], mode_hint: str | None, size: tuple[int, int],
             repeat: int) -> list[Row]:
    base = EmuOptions(width=size[0], height=size[1])
    results: dict[str, tuple[float, list]] = {}
    for mode, fields in MODES.items():
        times, frames = [], []
        for _ in range(repeat):
            start = time.perf_counter()
            frames = render(program, words, mode_hint, replace(base, **fields))
            times.append((time.perf_counter() - start) / len(frames))
        results[mode] = (statistics.median(times), frames)
    ref = results["fp64"][1]
    ref_rgb = np.concatenate([f.rgb565 for f in ref])
    ref_prov = np.concatenate([f.provenance for f in ref])
    rows = []
    for mode, (t, frames) in results.items():
        im = image_metrics(ref_rgb, np.concatenate([f.rgb565 for f in frames]))
        pm = provenance_metrics(ref_prov, np.concatenate([f.provenance for f in frames]))
        rows.append(Row(program.name, mode, len(frames), t, im.psnr, im.max_channel, im.share_differing, pm.hit_miss, pm.nearest_shape))
    return rows


def fmt_psnr(p: float) -> str:
    return "identical" if math.isinf(p) else f"{p:.1f}"


def markdown(rows: list[Row], size: tuple[int, int], repeat: int, command: str) -> str:
    lines = [
        "# Speed against accuracy: fp16 (ftz, ieee), fp32, fp64",
        "",
        f"Measured by `{command}` ({size[0]}x{size[1]} pixels, median of {repeat} runs per mode,",
        "one process, numpy on the CPU). Errors are against the fp64 rendering of the same program:",
        "PSNR over RGB888, the largest channel difference (0-255), the share of pixels that differ at",
        "all, silhouette pixels (hit in one, miss in the other) and pixels where both hit but a",
        "different shape is nearest. The plot `tradeoff.png` shows every program and mode as one point.",
        "",
        "![time per frame against PSNR](tradeoff.png)",
        "",
        "## Summary",
        "",
        "| mode | median time/frame | time vs fp64 | programs identical to fp64 | median PSNR (dB) | worst PSNR (dB) | silhouette pixels (all programs) | nearest-shape pixels (all programs) |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    programs = sorted({r.program for r in rows})
    fp64_times = {r.program: r.seconds_per_frame for r in rows if r.mode == "fp64"}
    for mode in MODES:
        mr = [r for r in rows if r.mode == mode]
        ratio = statistics.median(r.seconds_per_frame / fp64_times[r.program] for r in mr)
        identical = sum(math.isinf(r.psnr) for r in mr)
        finite = [r.psnr for r in mr]
        lines.append(
            f"| {mode} | {1000 * statistics.median(r.seconds_per_frame for r in mr):.1f} ms | {ratio:.2f}x "
            f"| {identical}/{len(programs)} | {fmt_psnr(statistics.median(finite))} | {fmt_psnr(min(finite))} "
            f"| {sum(r.silhouette for r in mr)} | {sum(r.nearest_shape for r in mr)} |"
        )
    lines += ["", *summary_sentences(rows)]
    lines += [
        "",
        "## Per program",
        "",
        "| program | mode | frames | time/frame (ms) | PSNR (dB) | max channel | differing | silhouette px | nearest-shape px |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        lines.append(
            f"| {r.program} | {r.mode} | {r.frames} | {1000 * r.seconds_per_frame:.1f} | {fmt_psnr(r.psnr)} "
            f"| {r.max_channel} | {100 * r.share_differing:.2f}% | {r.silhouette} | {r.nearest_shape} |"
        )
    return "\n".join(lines) + "\n"


def summary_sentences(rows: list[Row]) -> list[str]:
    """Plain-language findings computed from the table."""
    by_mode = {m: [r for r in rows if r.mode == m] for m in MODES}
    n = len(by_mode["fp64"])
    fp32_exact = sum(math.isinf(r.psnr) for r in by_mode["fp32"])
    worst16 = sorted(by_mode["fp16-ftz"], key=lambda r: r.psnr)[:4]
    ftz_vs_ieee = sum(
        1
        for a, b in zip(by_mode["fp16-ftz"], by_mode["fp16-ieee"], strict=True)
        if (a.psnr, a.share_differing, a.silhouette) != (b.psnr, b.share_differing, b.silhouette)
    )
    fp64_t = {r.program: r.seconds_per_frame for r in by_mode["fp64"]}
    t = {m: statistics.median(r.seconds_per_frame / fp64_t[r.program] for r in mr) for m, mr in by_mode.items()}
    differs16 = sum(not math.isinf(r.psnr) for r in by_mode["fp16-ftz"])
    return [
        f"fp32 renders {fp32_exact} of {n} programs bit-identical to fp64 in {t['fp32']:.2f}x its time (median "
        f"over programs); emulated fp16 (every operation rounded to float16) takes {t['fp16-ftz']:.2f}x (ftz) and "
        f"{t['fp16-ieee']:.2f}x (ieee) the time of fp64 and differs from it on {differs16} of {n} programs. "
        f"The largest fp16 errors are in {', '.join(f'{r.program} ({fmt_psnr(r.psnr)} dB)' for r in worst16)}. "
        f"Flush-to-zero and IEEE subnormals give different error figures on {ftz_vs_ieee} of {n} programs. "
        "See `numerics.md` for what causes each error and how to avoid it.",
    ]


def plot(rows: list[Row]) -> bytes:
    """PNG of time per frame (log x) against PSNR (y; identical frames at the top), with Pillow."""
    from PIL import Image, ImageDraw, ImageFont

    W, H, L, R, T, B = 900, 560, 80, 170, 40, 60
    img = Image.new("RGB", (W, H), "white")
    d = ImageDraw.Draw(img)
    font = ImageFont.load_default(size=13)
    times = [r.seconds_per_frame for r in rows]
    lo = math.floor(math.log10(min(times)))
    hi = math.ceil(math.log10(max(times)))
    hi = max(hi, lo + 1)
    psnrs = [r.psnr for r in rows if not math.isinf(r.psnr)]
    ymin = 10 * math.floor(min(psnrs + [PSNR_IDENTICAL - 10]) / 10)
    ymax = PSNR_IDENTICAL

    def x_of(t: float) -> float:
        return L + (math.log10(t) - lo) / (hi - lo) * (W - L - R)

    def y_of(p: float) -> float:
        p = PSNR_IDENTICAL if math.isinf(p) else min(p, PSNR_IDENTICAL)
        return T + (ymax - p) / (ymax - ymin) * (H - T - B)

    d.rectangle([L, T, W - R, H - B], outline="black")
    for e in range(lo, hi + 1):
        x = x_of(10.0**e)
        d.line([x, H - B, x, H - B + 5], fill="black")
        d.line([x, T, x, H - B], fill=(225, 225, 225))
        d.text((x - 18, H - B + 8), f"{1000 * 10.0**e:g} ms", fill="black", font=font)
    for p in range(int(ymin), int(ymax) + 1, 10):
        y = y_of(p)
        d.line([L - 5, y, L, y], fill="black")
        d.line([L, y, W - R, y], fill=(225, 225, 225))
        label = "identical" if p == PSNR_IDENTICAL else f"{p} dB"
        d.text((L - 70, y - 7), label, fill="black", font=font)
    d.text((L + (W - L - R) // 2 - 90, H - 25), "median time per frame (log scale)", fill="black", font=font)
    d.text((L, 12), "PSNR against fp64 (higher is more accurate; top row: bit-identical)", fill="black", font=font)
    for r in rows:
        x, y = x_of(r.seconds_per_frame), y_of(r.psnr)
        d.ellipse([x - 4, y - 4, x + 4, y + 4], fill=MODE_COLOURS[r.mode], outline="black")
    for i, (mode, colour) in enumerate(MODE_COLOURS.items()):
        y = T + 10 + 22 * i
        d.ellipse([W - R + 20, y - 5, W - R + 30, y + 5], fill=colour, outline="black")
        d.text((W - R + 38, y - 8), mode, fill="black", font=font)
    png = io.BytesIO()
    img.save(png, format="PNG")
    return png.getvalue()


def main(argv: list[str] | None = None) -> int:
    reuse_freed_memory()  # as the rend3r command does (rend3r/memory.py)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--programs", type=Path, default=ROOT / "programs")
    ap.add_argument("--size", default="256x192", help="image size WxH (default 256x192)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per mode; the median is reported")
    ap.add_argument("--out", type=Path, default=ROOT / "docs", help="folder for tradeoff.md and tradeoff.png")
    ap.add_argument("--only", nargs="*", help="program names to measure (default: all)")
    ap.add_argument("--scheduler", type=parse_scheduler, default="none",
                    help="where the programs are measured: none (one at a time, the default), local, tcp://HOST:PORT")
    args = ap.parse_args(argv)
    size = parse_size(args.size)
    try:  # before any measuring: a folder that cannot be made fails now, not after minutes
        out = make_output_folder(args.out)
    except Rend3rError as exc:
        print(f"rend3r: error: {exc}", file=sys.stderr)
        return 1
    inputs = []
    for program in (p for p in discover(args.programs) if not args.only or p.name in args.only):
        try:  # read here: a worker needs no files
            loaded = load_program(program.path)
        except Rend3rError as exc:
            print(f"{program.name}: skipped: {exc}", file=sys.stderr)
            continue
        inputs.append((program, loaded.words, loaded.mode_hint, size, args.repeat))
    try:
        with Campaign(args.scheduler) as campaign, Progress(len(inputs), "tradeoff") as bar:
            measured_all = campaign.map(measure, inputs, [i[0].name for i in inputs], bar)
    except Rend3rError as exc:
        print(f"rend3r: error: {exc}", file=sys.stderr)
        return 1
    rows: list[Row] = []
    for (program, *_), measured in zip(inputs, measured_all):
        if isinstance(measured, str):
            print(f"{program.name}: skipped: {measured}", file=sys.stderr)
            continue
        rows += measured
        for r in measured:
            print(
                f"{r.program:16} {r.mode:9} {1000 * r.seconds_per_frame:9.1f} ms/frame  PSNR {fmt_psnr(r.psnr):>9}  "
                f"max {r.max_channel:3}  differ {100 * r.share_differing:6.2f}%  silhouette {r.silhouette:6}  nearest {r.nearest_shape:6}",
                flush=True,
            )
    if not rows:
        print("nothing measured", file=sys.stderr)
        return 1
    command = "python benchmarks/bench_tradeoff.py " + " ".join(argv if argv is not None else sys.argv[1:])
    md, png = out / "tradeoff.md", out / "tradeoff.png"
    try:
        write_all([(md, markdown(rows, size, args.repeat, command.strip()).encode()), (png, plot(rows))])
    except Rend3rError as exc:
        print(f"rend3r: error: {exc}", file=sys.stderr)
        return 1
    print(f"wrote {md} and {png}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
