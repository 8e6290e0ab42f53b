"""``rend3r asm``: assemble a source file into one or more memory-image formats."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..errors import Rend3rError
from ..isa.extensions import EXTENSIONS
from ..isa.targets import TARGETS
from .formats import FORMATS, render
from .formats.recognise import refuse_wrong_kind


def output_paths(src: Path, out: str | None, formats: list[str], extensions: dict[str, str]) -> dict[str, str | None]:
    """Where each format goes; None means standard output.

    One format: ``-o OUT`` is the exact path (``-`` or no ``-o``: standard output).
    Several formats: ``-o`` is a stem (a trailing format extension is dropped; default:
    the source path without ``.asm``) and each format adds its own extension.
    """
    if len(formats) == 1:
        return {formats[0]: None if out in (None, "-") else out}
    if out == "-":
        raise Rend3rError("-o - (standard output) takes a single format")
    stem = out if out is not None else str(src.with_suffix("")) if src.suffix.lower() == ".asm" else str(src)
    for ext in sorted(extensions.values(), key=len, reverse=True):
        if stem.endswith(ext):
            stem = stem[: -len(ext)]
            break
    paths = {fmt: stem + extensions[fmt] for fmt in formats}
    if len(set(paths.values())) != len(paths):
        raise Rend3rError("two formats would be written to the same file; give fewer formats")
    return paths


@click.command(
    "asm",
    epilog="""\b
Examples:
  rend3r asm scene.asm                    print the mem image on standard output
  rend3r asm scene.asm -o main.mem        write main.mem ($readmemh, one word per line)
  rend3r asm scene.asm -f mem -f lst -o build/scene
                                          write build/scene.mem and build/scene.lst
                                          (build/ is made if missing)
  rend3r asm scene.asm -f bin -o scene.bin --byteorder little
  rend3r asm scene.asm --target rend3r-main -W error -I lib/
  rend3r asm mix.asm --isa-ext hybrid     accept ts (table select) for hybrid frames
""",
)
@click.argument("src", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", "out", metavar="FILE|STEM",
              help="Output file (one format; '-' = stdout) or stem that each format's extension is added to "
                   "(several formats); missing folders are made.")
@click.option("-f", "--format", "formats", multiple=True, type=click.Choice(list(FORMATS)),
              help="Output format; repeat for several (default: mem).")
@click.option("-I", "--include-dir", "include_dirs", multiple=True, metavar="DIR",
              help="Directory searched by .include after the including file's own directory; repeatable.")
@click.option("--target", type=click.Choice(sorted(TARGETS)),
              help="Warn about indices and program sizes beyond this device build's memories.")
@click.option("--byteorder", type=click.Choice(["big", "little"]), default="big", show_default=True,
              help="Byte order of each word in bin and ihex output.")
@click.option("--isa-ext", "isa_ext", multiple=True, type=click.Choice(sorted(EXTENSIONS), case_sensitive=False),
              help="Enable an ISA extension (hybrid: the ts table-select word); repeatable. "
                   "A source can say .isa_ext NAME instead.")
@click.option("-W", "warn", type=click.Choice(["error"]), help="-W error: treat warnings as errors.")
@click.option("--werror", is_flag=True, hidden=True)  # the old spelling of -W error
@click.option("--max-errors", type=click.IntRange(min=0), default=20, show_default=True, metavar="N",
              help="Stop after N errors (0: report every error).")
def asm_command(src: Path, out: str | None, formats: tuple[str, ...], include_dirs: tuple[str, ...],
                target: str | None, isa_ext: tuple[str, ...], byteorder: str, warn: str | None, werror: bool,
                max_errors: int) -> None:
    """Assemble SRC (a .asm file) into memory images for the REND3R device.

    Diagnostics go to standard error. On any error the exit status is 1 and no output
    file is created or changed; the files are written together once everything succeeded.
    """
    from ..fileio import write_all
    from .assembler import assemble_file

    refuse_wrong_kind(src, "source")
    fmts = list(dict.fromkeys(formats or ("mem",)))
    extensions = {name: FORMATS[name].extension for name in fmts}
    paths = output_paths(src, out, fmts, extensions)
    for fmt, path in paths.items():
        if path is None and FORMATS[fmt].binary and sys.stdout.isatty():
            raise Rend3rError(f"{fmt} output is binary: give -o FILE (or redirect standard output)")
    result = assemble_file(src, include_dirs, target, werror=werror or warn == "error", isa_ext=isa_ext,
                           max_errors=max_errors)
    if result.diagnostics:
        click.echo(result.format_diagnostics(), err=True)
    if not result.ok:
        raise Rend3rError(f"{src}: {len(result.errors)} error(s); no output written")
    rendered = {fmt: render(fmt, result.program, byteorder=byteorder) for fmt in fmts}
    write_all([(path, rendered[fmt]) for fmt, path in paths.items() if path is not None])
    for fmt, path in paths.items():
        if path is None:
            click.echo(rendered[fmt], nl=False)  # bytes go to the binary stdout
