"""All-or-nothing outputs of one command: every file is written or none is.

Each file goes through :func:`rend3r.fileio.write_atomic` (a reader never sees half a
file). When a later file fails, the files this call already wrote are rolled back: a new
file is removed, a replaced file gets its old content back (kept as a hard link beside
it until the call ends; where the filesystem has no hard links the old bytes are kept in
memory instead).
"""

from __future__ import annotations

import os
import secrets
from pathlib import Path

from ..errors import Rend3rError
from ..fileio import MAX_INPUT, read_limited, write_atomic


def write_all(outputs: list[tuple[str | os.PathLike[str], bytes]]) -> None:
    """Write every ``(path, data)`` atomically; on any failure none of them is changed."""
    paths = [Path(p) for p, _ in outputs]
    for i, p in enumerate(paths):
        if any(os.path.abspath(p) == os.path.abspath(q) for q in paths[:i]):
            raise Rend3rError(f"{p}: given twice as an output")
    done: list[tuple[Path, Path | bytes | None]] = []
    try:
        for path, (_, data) in zip(paths, outputs):
            backup = _keep(path)
            try:
                write_atomic(path, data)
            except BaseException:
                _drop(backup)
                raise
            done.append((path, backup))
    except BaseException:
        for path, backup in reversed(done):
            _restore(path, backup)
        raise
    for _, backup in done:
        _drop(backup)


def _keep(path: Path) -> Path | bytes | None:
    """A way back to ``path``'s current content: a hard link, its bytes, or None if absent."""
    if not path.is_file():
        return None
    link = path.with_name(f".{path.name}.{secrets.token_hex(6)}.old")
    try:
        os.link(path, link)
        return link
    except OSError:
        return read_limited(path, MAX_INPUT, what="file to replace")


def _restore(path: Path, backup: Path | bytes | None) -> None:
    """Put ``path`` back as it was before this call (best effort: the error is already raised)."""
    try:
        if backup is None:
            path.unlink(missing_ok=True)
        elif isinstance(backup, Path):
            os.replace(backup, path)
        else:
            write_atomic(path, backup)
    except (OSError, Rend3rError):
        pass


def _drop(backup: Path | bytes | None) -> None:
    if isinstance(backup, Path):
        backup.unlink(missing_ok=True)
