"""Golden-image baselines: a JSON manifest of frame-buffer hashes, PNGs beside it.

``programs/golden/manifest.json`` holds, per program, the size it was rendered at and the
SHA-256 of each fp16 (ftz) frame buffer: the (H, W) RGB565 values as little-endian uint16
bytes, row-major. ``<name>[.NNN].png`` beside it shows the same frame to people. Only
``pytest --update-goldens`` rewrites them.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fileio import write_atomic

MANIFEST = "manifest.json"
#: Size of the golden renderings: the device's own 512x384. A program may name a smaller
#: ``test-size`` in its header when rendering it at full size would slow the suite down.
GOLDEN_SIZE = (512, 384)
HASH_FORMAT = "sha256 of the RGB565 frame buffer as little-endian uint16, row-major"


def frame_hash(fb: np.ndarray) -> str:
    """SHA-256 (hex) of an (H, W) RGB565 frame buffer as little-endian uint16 bytes."""
    return hashlib.sha256(np.ascontiguousarray(fb, dtype="<u2").tobytes()).hexdigest()


@dataclass
class GoldenManifest:
    """Per program: the rendered size and one hash per frame."""

    path: Path
    programs: dict[str, dict] = field(default_factory=dict)

    @classmethod
    def load(cls, folder: Path) -> GoldenManifest:
        path = folder / MANIFEST
        if not path.exists():
            return cls(path)
        data = json.loads(path.read_text(encoding="utf-8"))
        return cls(path, data.get("programs", {}))

    def entry(self, name: str) -> dict | None:
        return self.programs.get(name)

    def record(self, name: str, size: tuple[int, int], hashes: list[str]) -> None:
        self.programs[name] = {"size": list(size), "frames": hashes}

    def save(self) -> None:
        data = {"format": HASH_FORMAT, "precision": "fp16", "subnormals": "ftz", "programs": dict(sorted(self.programs.items()))}
        self.path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(self.path, (json.dumps(data, indent=2) + "\n").encode("utf-8"))
