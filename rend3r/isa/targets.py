"""Memory sizes of the original device's builds, for target-aware warnings.

From the original device's public SystemVerilog source: indices beyond a size alias modulo that size.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Target:
    """Capacities of one device build."""

    name: str
    shapes: int
    lights: int
    triangles: int
    instructions: int
    description: str


TARGETS: dict[str, Target] = {
    t.name: t
    for t in (
        Target("rend3r-raytracing", 2, 2, 2, 32, "original board, raytracing branch"),
        Target("rend3r-main", 16, 8, 8, 128, "original board, main (rasterizing) branch"),
        Target("rend3r-taping", 16, 8, 1024, 1024, "original board, taping-min-dram branch"),
    )
}
