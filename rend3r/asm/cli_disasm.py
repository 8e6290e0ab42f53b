"""``rend3r disasm``: a memory image (any format) to canonical assembly source."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..errors import Rend3rError
from ..fileio import write_atomic
from .disasm import ISA_EXTENSIONS, MODES, disassemble
from .formats import FORMATS, read_file, read_stream
from .formats.recognise import refuse_wrong_kind


@click.command(
    "disasm",
    epilog="""\b
Examples:
  rend3r disasm main.mem                       # print source for a board's main.mem
  rend3r disasm scene.bin --byteorder little -o scene.asm
  rend3r disasm tris.hex --mode raster         # tr names for a rasterizer program
  rend3r disasm mix.mem --isa-ext hybrid       # ts words, sp/tr by the table they select
  cat main.mem | rend3r disasm -               # read standard input""",
)
@click.argument("src", metavar="IN")
@click.option("-o", "--output", "out", metavar="FILE",
              help="Write the source here (atomically; missing folders are made) instead of to stdout.")
@click.option(
    "--mode",
    type=click.Choice(list(MODES)),
    default="raytrace",
    show_default=True,
    help="raytrace names SE/SD pairs with sp and shape properties; raster with tr and triangle properties.",
)
@click.option(
    "-f",
    "--format",
    "fmt",
    type=click.Choice(list(FORMATS)),
    default=None,
    help="Format of IN (default: by extension, then by content).",
)
@click.option(
    "--byteorder",
    type=click.Choice(["big", "little"]),
    default="big",
    show_default=True,
    help="Byte order of each word in bin and ihex input.",
)
@click.option("--addresses", is_flag=True, help="Add each statement's word address (hex) as a trailing comment.")
@click.option(
    "--isa-ext",
    "isa_ext",
    multiple=True,
    type=click.Choice(ISA_EXTENSIONS, case_sensitive=False),
    help="Print the words of an ISA extension (hybrid: TS words as ts shape/ts triangle, the pairs after them "
    "as sp/tr) after an .isa_ext line; otherwise they stay .word.",
)
def disasm_command(src: str, out: str | None, mode: str, fmt: str | None, byteorder: str, addresses: bool,
                   isa_ext: tuple[str, ...]) -> None:
    """Disassemble memory image IN (mem, bin, coe, ihex or lst) into rend3r assembly.

    The output assembles back to exactly the same words: words that are no instruction
    become `.word` lines with a comment saying why. Use `-` as IN for standard input.
    """
    if isa_ext and mode != "raytrace":
        raise Rend3rError(f"--mode {mode} does not apply with --isa-ext hybrid: a hybrid program starts with the "
                          "shape table selected and its ts words choose the table")
    if src == "-":
        words = read_stream(sys.stdin.buffer, fmt, "<stdin>", byteorder)
    else:
        if fmt is None:
            refuse_wrong_kind(src, "image")
        words = read_file(src, fmt, byteorder)
    text = disassemble(words, mode, addresses, isa_ext)
    if out is None:
        click.echo(text, nl=False)
    else:
        if Path(out).resolve() == Path(src).resolve():
            raise Rend3rError(f"{out}: refusing to overwrite the input file")
        write_atomic(out, text.encode("utf-8"))
