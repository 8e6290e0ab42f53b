"""File input and output with limits: reads stop at a size cap (so ``/dev/zero``, a FIFO
or a huge sparse file ends with an error naming the limit), writes are atomic (a reader
never sees a half-written file, and a failed write leaves nothing behind), and a
command's outputs are all or nothing (:class:`Outputs`): every output is checked before
any work, staged under a hidden name beside its target, and renamed into place only when
the whole run has succeeded; when anything fails first, the staged files and the folders
the run created are removed and every file it would have replaced is left as it was.

One rule for every command's outputs: missing parent folders are created (and removed
again when the write fails); an output that cannot be written is refused with
``cannot write PATH: reason`` (:func:`check_writable`)."""

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
    the file is renamed over ``path`` with :func:`os.replace`. Missing parent folders are
    created first. On any failure the temporary file and the folders made are removed,
    ``path`` is left as it was, and a :class:`Rend3rError` is raised.
    A new file gets the mode a plain ``open(path, "wb")`` would give it; an existing
    file keeps its mode.
    """
    target = Path(path)
    directory = target.parent
    check_writable(target)
    made = make_folders(target)
    tmp = directory / f".rend3r-{secrets.token_hex(6)}.tmp"  # short: any target name fits
    try:  # one block from the file's creation on: an interrupt right after os.open returns
        # (before the next statement) still removes it; the random name is ours alone.
        # 0o666 filtered by the umask, as for an ordinary new file.
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        _keep_mode(target, tmp)
        os.replace(tmp, target)
    except BaseException as exc:
        if not isinstance(exc, FileExistsError):  # os.open met a file of that name: not ours
            tmp.unlink(missing_ok=True)
        remove_folders(made)
        if isinstance(exc, OSError):
            raise Rend3rError(f"cannot write {target}: {exc.strerror or exc}") from exc
        raise
    _fsync_directory(directory)


def check_writable(path: str | os.PathLike[str]) -> None:
    """Refuse, with ``cannot write PATH: reason``, an output that cannot be written: a name
    with a NUL byte or a part too long, a folder in its place, or its nearest existing
    ancestor folder a file or not writable. Missing folders in between are fine: they are
    made when the file is written (:func:`make_folders`)."""
    p = Path(path)
    if "\0" in str(p):
        raise Rend3rError(f"cannot write {str(p)!r}: a file name cannot hold a NUL byte")
    folder = p.parent
    while not os.path.lexists(folder) and folder != folder.parent:
        folder = folder.parent
    longest = _name_max(folder)
    for part in p.parts:
        if len(os.fsencode(part)) > longest:
            raise Rend3rError(f"cannot write {p}: a name in it is longer than {longest} bytes")
    try:
        if p.is_dir():
            raise Rend3rError(f"cannot write {p}: it is a folder")
        if not folder.is_dir():
            raise Rend3rError(f"cannot write {p}: {folder} is not a folder")
    except OSError as exc:
        raise Rend3rError(f"cannot write {p}: {exc.strerror or exc}") from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise Rend3rError(f"cannot write {p}: folder {folder} is not writable")


def make_folders(path: str | os.PathLike[str]) -> list[Path]:
    """Create the missing folders above the file ``path``, outermost first, and return them
    (for :func:`remove_folders`); on failure remove those made and raise ``cannot write``."""
    p = Path(path)
    missing = []
    folder = p.parent
    while not os.path.lexists(folder) and folder != folder.parent:
        missing.append(folder)
        folder = folder.parent
    made: list[Path] = []
    for f in reversed(missing):
        try:
            f.mkdir()
        except OSError as exc:
            remove_folders(made)
            raise Rend3rError(f"cannot write {p}: cannot create folder {f}: {exc.strerror or exc}") from None
        made.append(f)
    return made


def make_output_folder(path: str | os.PathLike[str]) -> Path:
    """Make sure the output folder ``path`` exists, creating it and its parents, for the
    commands that write a folder of files; ``cannot write PATH: reason`` otherwise."""
    p = Path(path)
    if os.path.lexists(p) and not p.is_dir():
        raise Rend3rError(f"cannot write {p}: it is a file, not a folder")
    if not p.is_dir():
        check_writable(p)
        try:
            p.mkdir(parents=True)
        except OSError as exc:
            raise Rend3rError(f"cannot write {p}: {exc.strerror or exc}") from None
    elif not os.access(p, os.W_OK | os.X_OK):
        raise Rend3rError(f"cannot write {p}: folder {p} is not writable")
    return p


def remove_folders(made: list[Path]) -> None:
    """Remove folders listed outermost first (innermost first, each only if still empty)."""
    for folder in reversed(made):
        try:
            folder.rmdir()
        except OSError:
            pass


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


class Outputs:
    """The files of one run; use as a context manager (an exception aborts the run)."""

    def __init__(self) -> None:
        self._reserved: dict[str, Path] = {}
        self._staged: dict[Path, Path] = {}  # target -> staged file
        self._made: list[Path] = []  # folders this run created, parents first

    def reserve(self, path: str | os.PathLike[str]) -> Path:
        """Check now that ``path`` can be written (:func:`check_writable`) and is named once."""
        p = Path(path)
        key = os.path.abspath(p)  # no file system access: safe before the checks
        if key in self._reserved:
            raise Rend3rError(f"{p}: named by two outputs of this run")
        check_writable(p)
        self._reserved[key] = p
        return p

    def write(self, path: str | os.PathLike[str], data: bytes) -> None:
        """Stage ``data`` for ``path`` (reserved or not); it appears there at :meth:`commit`."""
        p = Path(path)
        if os.path.abspath(p) not in self._reserved:
            self.reserve(p)
        self._made += make_folders(p)
        old = self._staged.pop(p, None)
        if old is not None:
            old.unlink(missing_ok=True)
        stage = p.with_name(f".rend3r-{secrets.token_hex(6)}.part")  # short: any target name fits
        self._staged[p] = stage  # before it exists: an interrupt at any point leaves it to abort()
        try:
            write_atomic(stage, data)
        except Rend3rError as exc:
            del self._staged[p]
            raise Rend3rError(str(exc).replace(str(stage), str(p))) from None

    def commit(self) -> None:
        """Move every staged file into place; if one cannot be, put back the ones already
        moved (the files they replaced come back from hard-link backups) and raise."""
        done: list[tuple[Path, Path | bool]] = []
        try:
            for target, stage in self._staged.items():
                backup = _backup(target)
                try:
                    os.replace(stage, target)
                except OSError as exc:
                    if isinstance(backup, Path):
                        backup.unlink(missing_ok=True)
                    raise Rend3rError(f"cannot write {target}: {exc.strerror or exc}") from None
                done.append((target, backup))
        except BaseException:
            for target, backup in reversed(done):
                _restore(target, backup)
            self.abort()
            raise
        for _, backup in done:
            if isinstance(backup, Path):
                backup.unlink(missing_ok=True)
        self._staged.clear()
        self._made.clear()

    def abort(self) -> None:
        """Remove the staged files and the folders this run created (if still empty)."""
        for stage in self._staged.values():
            stage.unlink(missing_ok=True)
        self._staged.clear()
        remove_folders(self._made)
        self._made.clear()

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, kind, value, tb) -> None:
        if kind is not None:
            self.abort()


def _name_max(folder: Path) -> int:
    """The longest file name ``folder``'s filesystem takes (255 where it does not say)."""
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def _backup(target: Path) -> Path | bool:
    """A hard link to the file ``target`` is about to replace; False when there is none
    (a new file); True when it exists but this filesystem has no hard links (the file is
    then not restored: the up-front checks leave the rename itself as the only risk)."""
    if not os.path.lexists(target):
        return False
    link = target.with_name(f".rend3r-{secrets.token_hex(6)}.old")
    try:
        os.link(target, link, follow_symlinks=False)
    except OSError:
        return True
    return link


def _restore(target: Path, backup: Path | bool) -> None:
    """Undo one committed rename (best effort: the error is already being raised)."""
    try:
        if backup is False:
            target.unlink(missing_ok=True)
        elif isinstance(backup, Path):
            os.replace(backup, target)
    except OSError:
        pass


def write_all(outputs: list[tuple[str | os.PathLike[str], bytes]]) -> None:
    """Write every ``(path, data)``, all or nothing (:class:`Outputs`)."""
    with Outputs() as out:
        for path, _ in outputs:
            out.reserve(path)
        for path, data in outputs:
            out.write(path, data)
        out.commit()
