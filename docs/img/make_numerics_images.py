"""Regenerate the pictures of docs/numerics.md: each fp16_* program (and the acne-free
references) rendered side by side in fp16 ftz, fp16 ieee and fp64, with the fp16-ftz
versus fp64 diff (changed pixels magenta).

    python docs/img/make_numerics_images.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from rend3r.emu import EmuOptions
from rend3r.golden.catalog import read_header
from rend3r.emu.image import rgb565_to_rgb888
from rend3r.golden.metrics import diff_image
from rend3r.golden.render_all import render_example

ROOT = Path(__file__).resolve().parents[2]
OUT = Path(__file__).resolve().parent
SIZE = (320, 240)
PANELS = [("fp16 ftz", "fp16", "ftz"), ("fp16 ieee", "fp16", "ieee"), ("fp64", "fp64", "ftz")]
PROGRAMS = ["fp16_distance", "fp16_cancel", "fp16_underflow", "fp16_acne", "fp16_grazing", "fp16_limits", "cylinder_cone"]


def sheet(name: str) -> Image.Image:
    program = read_header(ROOT / "programs" / f"{name}.asm")
    frames = {}
    for label, precision, sub in PANELS:
        options = EmuOptions(precision=precision, subnormals=sub, width=SIZE[0], height=SIZE[1])
        frames[label] = render_example(program, options)[0].rgb565
    images = [(label, rgb565_to_rgb888(fb)) for label, fb in frames.items()]
    images.append(("diff fp16 ftz vs fp64", diff_image(frames["fp64"], frames["fp16 ftz"])))
    font = ImageFont.load_default(size=14)
    w, h = SIZE
    out = Image.new("RGB", (len(images) * (w + 4) - 4, h + 20), "white")
    d = ImageDraw.Draw(out)
    for i, (label, rgb) in enumerate(images):
        out.paste(Image.fromarray(np.ascontiguousarray(rgb), "RGB"), (i * (w + 4), 20))
        d.text((i * (w + 4) + 4, 2), f"{name}: {label}", fill="black", font=font)
    return out


def main() -> None:
    for name in PROGRAMS:
        sheet(name).save(OUT / f"{name}.png")
        print(f"wrote {OUT / name}.png")


if __name__ == "__main__":
    main()
