"""Emulator options: one dataclass holding every behaviour switch.

The defaults are the paper's semantics. Each device deviation is a separate field so a
device profile can flip them one by one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from .arith import Arith, Precision, make_arith

Mode = Literal["raytrace", "raster", "hybrid"]
DepthRule = Literal["zbuffer", "painter", "index"]
LightModel = Literal["spec", "device"]
CameraModel = Literal["spec", "device"]


@dataclass(frozen=True)
class EmuOptions:
    """How to run a program and render its frames."""

    precision: Precision = "fp16"
    stage_precision: tuple[tuple[str, Precision], ...] = ()  # per-stage formats (rend3r.precision.stages)
    subnormals: Literal["ftz", "ieee"] = "ftz"
    tininess: Literal["after", "before"] = "after"  # ftz: tiny judged after rounding, or before (a quirk)
    mode: Mode = "raytrace"
    width: int = 512
    height: int = 384
    background: int = 0x0000  # RGB565 colour of pixels no shape covers
    camera: CameraModel = "spec"  # "device": fixed rays of the original hardware
    lr_target: int = 0  # address `lr` jumps to (the device jumps to 1)
    clear_on_nr: bool = True  # `nr` clears scene state and frame buffer (the device does not)
    depth: DepthRule = "zbuffer"  # raster mode: z-buffer, painter's order, or index order (device)
    light_model: LightModel = "spec"  # "device": light 0 only, directional, colour/intensity ignored
    intensity_fixed: bool = False  # the device's 13-bit converter of the light factor
    er_needs_zero: bool = False  # `er` halts only if the next word is zero too (device)
    clear_frames: bool = True  # False: raster pixels no triangle covers keep the previous frame's value
    display: Literal["rgb565", "rgb444"] = "rgb565"  # "rgb444": frames as the device's monitor shows them
    # Rasterizer switches (read by raster.py, see docs/raster.md and docs/device-profile.md)
    raster_camera: Literal["spec", "device"] = "spec"
    raster_shading: bool = True
    raster_rules: Literal["spec", "device"] = "spec"
    raster_column_offset: int = 0
    raster_next_triangle: bool = False
    jobs: int = 0  # threads rendering a frame (0: every core); the image does not depend on it

    @property
    def arith(self) -> Arith:
        return make_arith(self.precision, self.subnormals, self.tininess, self.stage_precision)

    @property
    def pixels(self) -> int:
        return self.width * self.height
