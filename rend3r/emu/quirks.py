"""Original-device behaviours as named switches (``--device-quirk NAME``, ``--profile``).

Each quirk sets one or more :class:`EmuOptions` fields; ``docs/device-profile.md``
documents each with its source in the original device's public RTL. A profile is a set
of quirks; an option given explicitly that a selected quirk would change is refused
(:func:`contradictions`), never silently overridden.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Iterable, Mapping

from ..errors import Rend3rError
from .options import EmuOptions


@dataclass(frozen=True)
class Quirk:
    name: str
    summary: str
    changes: tuple[tuple[str, object], ...]  # (EmuOptions field, value)


QUIRKS: dict[str, Quirk] = {
    q.name: q
    for q in (
        Quirk("device-camera", "fixed rays from 0xC4FD/0xC37B/0xBC00 stepped by 0x2500; +y down; camera "
              "rotation, fov, near and far ignored", (("camera", "device"),)),
        Quirk("light0-only", "only light 0, as a directional light; its colour and intensity ignored",
              (("light_model", "device"),)),
        Quirk("intensity-13bit", "I*16384 converted to a 13-bit signed integer that wraps above I ~ 0.25",
              (("intensity_fixed", True),)),
        Quirk("nr-keeps-state", "nr clears neither scene memory nor the frame buffer", (("clear_on_nr", False),)),
        Quirk("lr-to-1", "lr jumps to address 1, skipping the nr at 0", (("lr_target", 1),)),
        Quirk("er-needs-zero", "er halts only if the next word is zero too; otherwise it is skipped",
              (("er_needs_zero", True),)),
        Quirk("flush-subnormals", "float16 subnormal inputs and results are signed zero", (("subnormals", "ftz"),)),
        Quirk("tiny-before-rounding", "flush-to-zero judges a result by its value before rounding: "
              "2**-14 - 2**-25 and up flush instead of rounding to 2**-14 (unsure; not in the profile)",
              (("tininess", "before"),)),
        Quirk("raster-fixed-camera", "rasterizer projects with near 1, canvas 10 x 7.5 from the origin, no "
              "rotation (camera properties ignored)", (("raster_camera", "device"),)),
        Quirk("raster-unshaded", "rasterizer paints the flat triangle colour (no lighting)",
              (("raster_shading", False),)),
        Quirk("raster-index-order", "rasterizer has no depth order: triangles paint in index order, later "
              "ones over earlier ones", (("depth", "index"),)),
        Quirk("raster-pixel-snap", "vertices rounded to whole pixels, sampled at integer positions, edges "
              "inclusive, zero-area triangles cover the screen", (("raster_rules", "device"),)),
        Quirk("raster-column-offset", "rasterized pixels land 3 columns right of their coverage",
              (("raster_column_offset", 3),)),
        Quirk("raster-next-triangle", "the slot for triangle A is drawn with triangle A+1's data",
              (("raster_next_triangle", True),)),
        Quirk("frames-not-cleared", "a new frame starts from the previous frame's pixels (raster)",
              (("clear_frames", False),)),
        Quirk("rgb444-display", "the display shows the low 12 bits of each pixel as RGB444",
              (("display", "rgb444"),)),
    )
}

#: Quirks the board may or may not have, left out of its profile (docs/device-profile.md).
UNSURE: tuple[str, ...] = ("tiny-before-rounding",)
PROFILES: dict[str, tuple[str, ...]] = {"rend3r-2022": tuple(q for q in QUIRKS if q not in UNSURE)}


def quirk_names(profile: str | None, quirks: Iterable[str]) -> list[str]:
    """The quirks a ``--profile`` and ``--device-quirk`` list select, in registry order."""
    chosen: set[str] = set()
    if profile is not None:
        if profile not in PROFILES:
            raise Rend3rError(f"unknown profile {profile!r}; known: {', '.join(PROFILES)}")
        chosen.update(PROFILES[profile])
    for name in quirks:
        if name not in QUIRKS:
            raise Rend3rError(f"unknown device quirk {name!r}; known: {', '.join(QUIRKS)}")
        chosen.add(name)
    return [n for n in QUIRKS if n in chosen]


def contradictions(given: Mapping[str, object], names: Iterable[str]) -> list[tuple[str, str, object]]:
    """(field, quirk, value) for each quirk that would set a field given explicitly
    (``given``: EmuOptions field -> value) to a different value."""
    return [(field, q, value) for q in names for field, value in QUIRKS[q].changes
            if field in given and given[field] != value]


def apply_quirks(options: EmuOptions, names: Iterable[str]) -> EmuOptions:
    """``options`` with the named quirks switched on."""
    changes: dict[str, object] = {}
    for name in names:
        changes.update(QUIRKS[name].changes)
    return replace(options, **changes)
