"""Render counters and the paper's cycle model for the device."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

#: Raycaster pipeline depth in the paper's model, and the device clock.
PIPELINE_CYCLES = 205
CLOCK_HZ = 100e6


#: Rasterizer: 63 cycles of projection and 4 of coverage set-up, then one pixel per cycle.
RASTER_SETUP_CYCLES = 63 + 4


def device_cycles(shapes: int, lights: int, pixels: int) -> int:
    """The paper's raytracing estimate: (shapes + 205) * (lights + 1) * pixels."""
    return (shapes + PIPELINE_CYCLES) * (lights + 1) * pixels


def raster_cycles(triangles: int, pixels: int) -> int:
    """The paper's rasterization estimate: (63 + 4 + pixels) cycles per triangle."""
    return triangles * (RASTER_SETUP_CYCLES + pixels)


@dataclass
class FrameStats:
    """What one frame cost."""

    number: int = 0
    pixels: int = 0
    shapes: int = 0  # shapes that are on
    lights: int = 0  # lights that are on
    rays: int = 0  # primary rays cast
    shadow_rays: int = 0
    tests: int = 0  # ray-shape tests done
    skipped: int = 0  # ray-shape tests culled (provably no effect on the pixel)
    nan_tests: int = 0  # tests with a NaN or infinite value (counted as misses)
    nan_rays: int = 0  # pixels whose primary or shadow ray met a NaN or infinity
    hits: int = 0  # pixels showing a shape
    seconds: float = 0.0
    mode: str = "raytrace"  # or "raster": shapes are triangles, and the cycle model differs

    @property
    def device_cycles(self) -> int:
        if self.mode == "raster":
            return raster_cycles(self.shapes, self.pixels)
        return device_cycles(self.shapes, self.lights, self.pixels)

    @property
    def device_seconds(self) -> float:
        return self.device_cycles / CLOCK_HZ


@dataclass
class RunStats:
    """Per-frame stats of a run, and totals."""

    frames: list[FrameStats] = field(default_factory=list)
    instructions: int = 0
    halt: str = ""
    at_once: int = 1  # frames rendered side by side (then the run takes less than their sum)
    seconds: float = 0.0  # the run's wall time

    def total(self, name: str) -> float:
        return sum(getattr(f, name) for f in self.frames)

    @property
    def nan_rays(self) -> int:
        return int(self.total("nan_rays"))

    def report(self) -> str:
        """A human-readable table for ``--stats``."""
        counters = [f.name for f in fields(FrameStats) if f.name not in ("number", "seconds", "mode")]
        lines = [f"instructions executed: {self.instructions} (halted by {self.halt})"]
        for f in self.frames:
            parts = ", ".join(f"{n.replace('_', ' ')} {getattr(f, n)}" for n in counters)
            lines.append(
                f"frame {f.number}: {f.seconds * 1e3:.1f} ms; {parts}; device estimate "
                f"{f.device_cycles} cycles = {f.device_seconds:.3f} s at {CLOCK_HZ / 1e6:.0f} MHz"
            )
        if len(self.frames) > 1:
            side = (f" ({self.at_once} frames at a time; the run took {self.seconds:.3f} s, its outputs included)"
                    if self.at_once > 1 else "")
            lines.append(
                f"total: {self.total('seconds'):.3f} s for {len(self.frames)} frames{side}; device estimate "
                f"{self.total('device_seconds'):.3f} s"
            )
        return "\n".join(lines)
