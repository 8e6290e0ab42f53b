"""Emulator options: one dataclass holding every behaviour switch.

The defaults are the paper's semantics. Each device deviation is a separate field so a
device profile can flip them one by one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from .arith import Arith, Precision, make_arith

Mode = Literal["raytrace", "raster"]
DepthRule = Literal["zbuffer", "painter"]
CameraModel = Literal["spec", "device"]


@dataclass(frozen=True)
class EmuOptions:
    """How to run a program and render its frames."""

    precision: Precision = "fp16"
    subnormals: Literal["ftz", "ieee"] = "ftz"
    mode: Mode = "raytrace"
    width: int = 512
    height: int = 384
    background: int = 0x0000  # RGB565 colour of pixels no shape covers
    camera: CameraModel = "spec"  # "device": fixed rays of the original hardware
    lr_target: int = 0  # address `lr` jumps to (the device jumps to 1)
    clear_on_nr: bool = True  # `nr` clears scene state and frame buffer (the device does not)
    cull: bool = True  # skip shape tests that provably cannot change a pixel
    depth: DepthRule = "zbuffer"  # raster mode: hidden surfaces by z-buffer or painter's order

    @property
    def arith(self) -> Arith:
        return make_arith(self.precision, self.subnormals)

    @property
    def pixels(self) -> int:
        return self.width * self.height
