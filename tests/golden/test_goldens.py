"""Golden images: every example program's fp16 frames match the stored hashes exactly;
fp32 and fp64 frames stay within stated tolerances of them.

``pytest --update-goldens`` rewrites ``programs/golden/`` (hashes and PNGs); nothing else
does. On a failure the actual, expected and diff PNGs are written to a folder named in the
message.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

from rend3r.emu import EmuOptions, Frame
from rend3r.emu.image import save_png
from rend3r.golden.catalog import ExampleProgram, discover
from rend3r.golden.compare import load_image, save_rgb888_png
from rend3r.golden.metrics import as_rgb888, diff_image, image_metrics, region_interior_mask
from rend3r.golden.render_all import render_example
from rend3r.golden.store import GOLDEN_SIZE, GoldenManifest, frame_hash

ROOT = Path(__file__).resolve().parents[2]
PROGRAMS_DIR = ROOT / "programs"
GOLDEN_DIR = PROGRAMS_DIR / "golden"
PROGRAMS = discover(PROGRAMS_DIR)
IDS = [p.name for p in PROGRAMS]


@dataclass(frozen=True)
class Tolerance:
    """Bounds for an fp32/fp64 frame against the fp16 golden.

    ``max_share`` (share of differing pixels) and ``min_psnr`` cover the whole frame.
    ``max_channel`` covers only pixels away from edges (3x3 neighbourhood of one shape in
    the fp16 frame, ``region_interior_mask``), because at a silhouette one pixel flipping
    between hit and miss is a full-scale difference; ``None`` where shadow boundaries or
    terminators inside a shape flip pixels too, so no bound below 255 would hold.
    """

    max_channel: int | None
    max_share: float
    min_psnr: float
    why: str


#: Measured fp16-vs-fp64 figures at the golden size, loosened by a margin (share x1.5,
#: PSNR - 3 dB): a change in the renderer's numerics that moves them further fails.
TOLERANCES: dict[str, Tolerance] = {
    "sphere": Tolerance(16, 0.003, 41.0, "shading rounds by at most one RGB565 step away from the silhouette"),
    "registers": Tolerance(16, 0.003, 41.0, "same scene as sphere"),
    "animation": Tolerance(64, 0.009, 39.0, "shadow edges of the orbiting sphere"),
    "camera": Tolerance(None, 0.021, 33.0, "near-clip cut and shadow edges"),
    "cylinder_cone": Tolerance(None, 0.063, 30.5, "the cone's shadow edge on the cylinder; terminators"),
    "shadow": Tolerance(None, 0.012, 34.5, "shadow edge"),
    "hybrid": Tolerance(None, 0.011, 34.5, "shadow edges on the floor, the floor's horizon"),
    "hybrid_mix": Tolerance(40, 0.0075, 35.0, "sphere silhouettes and where the red sphere pierces a triangle"),
    "lights": Tolerance(None, 0.033, 32.0, "terminators of four lights"),
    "transforms": Tolerance(None, 0.065, 31.5, "grazing cone and cylinder edges, shadow edges"),
    "stress4096": Tolerance(40, 0.5, 18.5, "4,096 small spheres: many silhouettes at 64x48"),
    "fp16_acne": Tolerance(None, 0.17, 15.0, "acne and z-fighting by design"),
    "fp16_cancel": Tolerance(None, 0.27, 19.5, "cancellation in the quadratic by design"),
    "fp16_distance": Tolerance(None, 0.24, 18.0, "distance overflow beyond 256 units by design"),
    "fp16_grazing": Tolerance(None, 0.03, 33.0, "overflow near the vanishing point, grazing edges"),
    "fp16_limits": Tolerance(None, 0.34, 18.0, "shapes float16 cannot represent vanish by design"),
    "fp16_underflow": Tolerance(None, 0.027, 28.5, "flush-to-zero squares by design"),
    "tri_cube": Tolerance(4, 0.0005, 46.0, "flat shading is exact away from edges; vertices snap differently"),
    "tri_sphere": Tolerance(4, 0.0005, 48.0, "flat shading is exact away from edges; vertices snap differently"),
    "tri_overlap": Tolerance(4, 0.001, 32.0, "the slanted blue triangle's crossing edges"),
}


def size_of(program: ExampleProgram) -> tuple[int, int]:
    return program.test_size or GOLDEN_SIZE


@lru_cache(maxsize=None)
def frames_of(name: str, precision: str, subnormals: str = "ftz") -> tuple[Frame, ...]:
    """The program's frames in one precision at its golden size (rendered once per session)."""
    program = next(p for p in PROGRAMS if p.name == name)
    w, h = size_of(program)
    options = EmuOptions(precision=precision, subnormals=subnormals, width=w, height=h)
    return tuple(render_example(program, options))


def _artifacts(folder: Path, stem: str, actual: np.ndarray, expected: np.ndarray) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    save_rgb888_png(as_rgb888(actual), folder / f"{stem}.actual.png")
    save_rgb888_png(as_rgb888(expected), folder / f"{stem}.expected.png")
    if actual.shape[:2] == expected.shape[:2]:
        save_rgb888_png(diff_image(expected, actual), folder / f"{stem}.diff.png")
    return folder


def test_every_program_has_a_header() -> None:
    assert len(PROGRAMS) >= 15
    for p in PROGRAMS:
        lines = p.path.read_text(encoding="utf-8").splitlines()
        header = "\n".join(line for line in lines[: next(i for i, ln in enumerate(lines) if ln.strip() and not ln.startswith(";"))])
        assert header.startswith(f"; {p.path.name}:"), f"{p.path.name}: header must start with '; {p.path.name}:'"
        for key in ("Shows:", "Run:", "Look:"):
            assert key in header, f"{p.path.name}: header lacks {key}"


@pytest.mark.parametrize("program", PROGRAMS, ids=IDS)
def test_fp16_matches_golden_hash(program: ExampleProgram, update_goldens: bool, tmp_path: Path) -> None:
    frames = [f.rgb565 for f in frames_of(program.name, "fp16")]
    manifest = GoldenManifest.load(GOLDEN_DIR)
    hashes = [frame_hash(fb) for fb in frames]
    if update_goldens:
        for i, fb in enumerate(frames):
            save_png(fb, GOLDEN_DIR / f"{program.frame_name(i)}.png")
        manifest.record(program.name, size_of(program), hashes)
        manifest.save()
        return
    entry = manifest.entry(program.name)
    assert entry is not None, f"no golden for {program.name}: run pytest --update-goldens and review the PNGs"
    assert tuple(entry["size"]) == size_of(program), f"{program.name}: golden rendered at {entry['size']}"
    assert len(entry["frames"]) == len(frames), f"{program.name}: {len(frames)} frames, golden has {len(entry['frames'])}"
    for i, (fb, want) in enumerate(zip(frames, hashes, strict=True)):
        if want == entry["frames"][i]:
            continue
        stem = program.frame_name(i)
        expected = load_image(GOLDEN_DIR / f"{stem}.png")
        folder = _artifacts(tmp_path / "golden-failure", stem, fb, expected)
        m = image_metrics(expected, fb)
        pytest.fail(f"{stem}: fp16 frame differs from the golden ({m.describe()}); actual/expected/diff PNGs in {folder}")


def test_manifest_has_no_stale_programs() -> None:
    manifest = GoldenManifest.load(GOLDEN_DIR)
    assert set(manifest.programs) <= set(IDS), f"goldens for removed programs: {sorted(set(manifest.programs) - set(IDS))}"


def test_every_program_has_a_tolerance() -> None:
    missing = {p.name for p in PROGRAMS} - set(TOLERANCES)
    assert not missing, f"state fp32/fp64 tolerances for {sorted(missing)}"


@pytest.mark.parametrize("precision", ["fp32", "fp64"])
@pytest.mark.parametrize("program", PROGRAMS, ids=IDS)
def test_wider_precisions_within_tolerance(program: ExampleProgram, precision: str, tmp_path: Path) -> None:
    tol = TOLERANCES[program.name]
    golden16 = frames_of(program.name, "fp16")
    for i, frame in enumerate(frames_of(program.name, precision)):
        stem = program.frame_name(i)
        expected = load_image(GOLDEN_DIR / f"{stem}.png")
        whole = image_metrics(expected, frame.rgb565)
        inner = image_metrics(expected, frame.rgb565, region_interior_mask(golden16[i].provenance))
        ok = whole.within(None, tol.max_share, tol.min_psnr) and inner.within(tol.max_channel)
        if not ok:
            folder = _artifacts(tmp_path / "golden-failure", f"{stem}.{precision}", frame.rgb565, expected)
            pytest.fail(
                f"{stem}: {precision} against the fp16 golden: {whole.describe()}; away from edges: max channel "
                f"{inner.max_channel}. Allowed: share {tol.max_share}, PSNR >= {tol.min_psnr} dB, max channel away "
                f"from edges {tol.max_channel} ({tol.why}). Actual/expected/diff PNGs in {folder}"
            )


def test_registers_program_equals_sphere() -> None:
    """registers.asm spells sphere.asm's scene with aliases: the frame buffers must agree."""
    assert np.array_equal(frames_of("registers", "fp16")[0].rgb565, frames_of("sphere", "fp16")[0].rgb565)
