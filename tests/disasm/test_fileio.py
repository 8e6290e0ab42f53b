"""write_atomic: complete files or nothing, never a stray temporary."""

import os
import stat

import pytest

from rend3r.errors import Rend3rError
from rend3r.fileio import write_atomic


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


def test_missing_directory_is_a_clear_error(tmp_path):
    with pytest.raises(Rend3rError, match="cannot write"):
        write_atomic(tmp_path / "nope" / "out.mem", b"x")


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
