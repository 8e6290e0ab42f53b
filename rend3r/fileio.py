"""File input and output with limits: reads stop at a size cap (so ``/dev/zero``, a FIFO
or a huge sparse file ends with an error naming the limit), and writes are atomic (a
reader never sees a half-written file, and a failed write leaves nothing behind)."""

from __future__ import annotations

import os
import secrets
from pathlib import Path

from .errors import Rend3rError


MAX_INPUT = 256 << 20
"""Default cap on one input file (256 MiB): far above any program the device's memory or
an octree this tool builds can hold, far below what would exhaust a machine."""


def read_limited(path: str | os.PathLike[str], limit: int = MAX_INPUT, *, what: str = "input") -> bytes:
    """The bytes of ``path``, refused with a :class:`Rend3rError` beyond ``limit`` bytes.

    A regular file's size is checked with ``fstat`` before reading; anything else (a pipe,
    a character device such as ``/dev/zero``) is read in chunks and refused as soon as it
    passes the limit, so no more than ``limit`` + one chunk is ever held.
    """
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            size = os.fstat(fh.fileno()).st_size
            if size > limit:
                raise Rend3rError(f"{name}: {what} is {size:,} bytes; the limit is {limit:,} bytes")
            chunks: list[bytes] = []
            total = 0
            while chunk := fh.read(1 << 20):
                total += len(chunk)
                if total > limit:
                    raise Rend3rError(f"{name}: {what} is larger than the limit of {limit:,} bytes")
                chunks.append(chunk)
    except OSError as exc:
        raise Rend3rError(f"{name}: cannot read: {exc.strerror or exc}") from None
    return b"".join(chunks)


def write_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically.

    The bytes go to a temporary file in the same directory, are flushed and fsynced, and
    the file is renamed over ``path`` with :func:`os.replace`. On any failure the temporary
    file is removed, ``path`` is left as it was, and a :class:`Rend3rError` is raised.
    A new file gets the mode a plain ``open(path, "wb")`` would give it; an existing
    file keeps its mode.
    """
    target = Path(path)
    directory = target.parent
    tmp = directory / f".{target.name}.{secrets.token_hex(6)}.tmp"
    try:
        # 0o666 filtered by the umask, as for an ordinary new file.
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    except OSError as exc:
        raise Rend3rError(f"{target}: cannot write: {exc.strerror or exc}") from exc
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        _keep_mode(target, tmp)
        os.replace(tmp, target)
    except BaseException as exc:
        tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError):
            raise Rend3rError(f"{target}: cannot write: {exc.strerror or exc}") from exc
        raise
    _fsync_directory(directory)


def _keep_mode(target: Path, tmp: Path) -> None:
    """Give the replacement the permissions of the file it replaces, if there is one."""
    try:
        mode = target.stat().st_mode & 0o7777
    except FileNotFoundError:
        return
    os.chmod(tmp, mode)


def _fsync_directory(directory: Path) -> None:
    """Persist the rename itself (best effort: not every platform can open a directory)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
