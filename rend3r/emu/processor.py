"""The instruction processor: fetch, decode, execute; ``nf`` hands the scene to a renderer.

Semantics (paper, section III): ``nr`` clears scene state and the frame buffer, ``nf``
renders the current scene into a frame, ``lr`` jumps to address 0, ``er`` halts. Running
past the last word halts as ``er`` does (memory beyond the program is zero, and a zero
word is ``er``). Device deviations are fields of :class:`EmuOptions`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

from ..errors import Rend3rError
from ..isa import CameraSet, FrameOp, Func, LightSet, ShapeSet, Table, TrailingSE, Unknown, decode_word
from ..isa.tables import OPCODE, Opcode
from ..isa.extensions import decode_table_select
from .options import EmuOptions
from .scene import Scene

#: Called at each ``nf`` with the scene and the frame number (0-based).
RenderHook = Callable[[Scene, int], None]


@dataclass(frozen=True)
class Execution:
    """How a run ended."""

    frames: int  # number of nf executed
    instructions: int  # instructions executed (an SE/SD pair counts once)
    halt: str  # "er", "end" (ran past the last word) or "frames" (the --frames bound)


def _decode_at(words: Sequence[int], addr: int):
    word = words[addr]
    if OPCODE.get(word) == Opcode.SE:
        sd = words[addr + 1] if addr + 1 < len(words) else None
        return decode_word(word, sd), 2
    return decode_word(word), 1


def _where(pc: int) -> str:
    return f"address {pc} (0x{pc:04x})"


def execute(
    words: Sequence[int],
    options: EmuOptions,
    frames: int | None = None,
    on_nf: RenderHook | None = None,
    scene: Scene | None = None,
    decoded: dict[int, tuple[object, int]] | None = None,
) -> Execution:
    """Run ``words`` until ``er``, the end, or ``frames`` frames; call ``on_nf`` at each nf.

    Raises Rend3rError for an unknown opcode or trailing SE (with its address), for a
    looping program without a ``frames`` bound, and for a loop that renders nothing.
    ``decoded`` caches decoded words by address (pass the same dict to run ``words`` again).
    """
    if frames is not None and frames < 1:
        raise Rend3rError(f"--frames must be at least 1, not {frames}")
    scene = scene if scene is not None else Scene()
    table = Table.TRIANGLE if options.mode == "raster" else Table.SHAPE
    decoded = {} if decoded is None else decoded  # address -> (instruction, size); callers may share it
    pc = count = executed = 0
    frames_at_last_lr = -1
    while pc < len(words):
        if pc not in decoded:
            decoded[pc] = _decode_at(words, pc)
        ins, size = decoded[pc]
        executed += 1
        if isinstance(ins, Unknown):
            selected = decode_table_select(ins.word) if options.mode == "hybrid" else None
            if selected is None:
                hint = ("; it is a TS table-select word (docs/isa-extensions.md): run with --mode hybrid"
                        if decode_table_select(ins.word) is not None else "")
                raise Rend3rError(f"{_where(pc)}: unknown opcode 0b{OPCODE.get(ins.word):03b} in word 0x{ins.word:08x}{hint}")
            table = selected
            pc += size
            continue
        if isinstance(ins, TrailingSE):
            raise Rend3rError(f"{_where(pc)}: SE word 0x{ins.word:08x} is the last word; its SD is missing")
        pc += size
        if isinstance(ins, CameraSet):
            scene.set_camera(ins)
        elif isinstance(ins, LightSet):
            scene.set_light(ins)
        elif isinstance(ins, ShapeSet):
            scene.set_object(ins, table, scene.triangles if options.mode == "hybrid" and table is Table.TRIANGLE else None)
        elif isinstance(ins, FrameOp):
            if ins.func is Func.ER:
                if not options.er_needs_zero or pc >= len(words) or words[pc] == 0:
                    return Execution(count, executed, "er")
                continue  # the device skips an er whose next word is not zero
            if ins.func is Func.NR:
                if options.clear_on_nr:
                    scene.clear()
            elif ins.func is Func.NF:
                if on_nf is not None:
                    on_nf(scene, count)
                count += 1
                if frames is not None and count >= frames:
                    return Execution(count, executed, "frames")
            else:  # LR
                if frames is None:
                    raise Rend3rError(
                        f"{_where(pc - size)}: the program loops (lr); pass --frames N to bound how many frames to render"
                    )
                if count == frames_at_last_lr:
                    raise Rend3rError(f"{_where(pc - size)}: the program loops (lr) without rendering a frame (no nf in the loop)")
                frames_at_last_lr = count
                pc = options.lr_target
    return Execution(count, executed, "end")
