"""write_atomic: complete files or nothing, never a stray temporary; missing parent
folders made (and removed again when the write fails); impossible paths refused as
``cannot write PATH: reason``."""

import os
import stat

import pytest

from rend3r.errors import Rend3rError
from rend3r.fileio import Outputs, make_output_folder, write_atomic


def test_writes_new_file_with_umask_mode(tmp_path):
    target = tmp_path / "out.mem"
    write_atomic(target, b"00000000\n")
    assert target.read_bytes() == b"00000000\n"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
    assert os.listdir(tmp_path) == ["out.mem"]


def test_replaces_existing_file_and_keeps_its_mode(tmp_path):
    target = tmp_path / "out.bin"
    target.write_bytes(b"old contents")
    target.chmod(0o640)
    write_atomic(target, b"\x00\x01")
    assert target.read_bytes() == b"\x00\x01"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    assert os.listdir(tmp_path) == ["out.bin"]


def test_relative_path_in_current_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write_atomic("plain.mem", b"x")
    assert (tmp_path / "plain.mem").read_bytes() == b"x"


def test_missing_parent_folders_are_made(tmp_path):
    write_atomic(tmp_path / "a" / "b" / "out.mem", b"x")
    assert (tmp_path / "a" / "b" / "out.mem").read_bytes() == b"x"


def test_a_parent_that_is_a_file_is_refused_by_name(tmp_path):
    (tmp_path / "f").write_text("keep")
    target = tmp_path / "f" / "sub" / "out.mem"
    with pytest.raises(Rend3rError, match=f"^cannot write {target}: {tmp_path / 'f'} is not a folder$"):
        write_atomic(target, b"x")
    assert (tmp_path / "f").read_text() == "keep"


def test_an_unwritable_folder_is_refused_by_name(tmp_path, monkeypatch):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    real_access = os.access  # root may write anywhere: answer as for an ordinary user
    monkeypatch.setattr(os, "access", lambda p, mode: real_access(p, mode) and os.fspath(p) != os.fspath(locked))
    with pytest.raises(Rend3rError, match="^cannot write .*: folder .*locked is not writable$"):
        write_atomic(locked / "new" / "out.mem", b"x")
    assert list(locked.iterdir()) == []


def test_a_folder_that_refuses_files_leaves_no_folder_behind(tmp_path):
    # /proc takes no new files or folders, even from root: the OS's reason is given.
    with pytest.raises(Rend3rError, match="^cannot write /proc/rend3r-test/out.mem: cannot create folder "):
        write_atomic("/proc/rend3r-test/out.mem", b"x")


def test_made_folders_are_removed_when_the_write_fails(tmp_path, monkeypatch):
    def boom(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", boom)
    with pytest.raises(Rend3rError, match="^cannot write .*out.mem: No space left on device$"):
        write_atomic(tmp_path / "a" / "b" / "out.mem", b"x")
    assert list(tmp_path.iterdir()) == []


def test_output_folder_is_made_or_refused(tmp_path):
    assert make_output_folder(tmp_path / "a" / "b").is_dir()
    (tmp_path / "file").write_text("x")
    with pytest.raises(Rend3rError, match="^cannot write .*file: it is a file, not a folder$"):
        make_output_folder(tmp_path / "file")
    with pytest.raises(Rend3rError, match="^cannot write .*file/sub: .*file is not a folder$"):
        make_output_folder(tmp_path / "file" / "sub")


def test_failure_during_rename_leaves_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "dir_in_the_way"
    target.mkdir()
    (target / "keep").write_text("x")
    with pytest.raises(Rend3rError, match="cannot write"):
        write_atomic(target, b"data")
    assert sorted(os.listdir(tmp_path)) == ["dir_in_the_way"]
    assert os.listdir(target) == ["keep"]


def test_interrupted_write_leaves_nothing(tmp_path, monkeypatch):
    target = tmp_path / "out.mem"
    target.write_bytes(b"previous")

    def boom(fd):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "fsync", boom)
    with pytest.raises(KeyboardInterrupt):
        write_atomic(target, b"new")
    assert target.read_bytes() == b"previous"
    assert os.listdir(tmp_path) == ["out.mem"]


def test_an_interrupt_as_the_temporary_file_is_opened_leaves_nothing(tmp_path, monkeypatch):
    """Ctrl-C delivered just after os.open has created the file (before the next statement)."""
    real_open = os.open

    def open_then_interrupt(path, flags, mode=0o777):
        os.close(real_open(path, flags, mode))
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "open", open_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        write_atomic(tmp_path / "sub" / "out.mem", b"new")
    assert os.listdir(tmp_path) == []


def test_an_interrupt_as_an_output_is_staged_leaves_nothing(tmp_path, monkeypatch):
    """Ctrl-C after the staged file is in place but before Outputs recorded it."""
    real_replace = os.replace

    def replace_then_interrupt(src, dst):
        real_replace(src, dst)
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", replace_then_interrupt)
    with pytest.raises(KeyboardInterrupt), Outputs() as outputs:
        outputs.write(tmp_path / "frame.png", b"png")
    assert os.listdir(tmp_path) == []
