"""The Python writers' one helper (femtools.files.replacing), where the disk or the target says
no: a target that is not a regular file is refused, and a read-only folder ends in one line
naming the cause, not in a traceback from the clean-up (the review's A5-29/30)."""
import errno
import os
import pathlib

import pytest

from femtools import files


def test_a_fifo_target_is_refused_and_left_as_it_was(tmp_path):
    fifo = tmp_path / "plot.png"
    os.mkfifo(fifo)
    with pytest.raises(SystemExit) as stop:
        with files.replacing(fifo) as tmp:
            tmp.write_bytes(b"never")
    assert "not a regular file" in str(stop.value)
    assert fifo.is_fifo()
    assert [p.name for p in tmp_path.iterdir()] == ["plot.png"]


def test_a_read_only_folder_ends_in_one_line_naming_the_cause(tmp_path, monkeypatch):
    def read_only(*_args, **_kwargs):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    # As on a read-only mount (root may write through chmod, so the file system's answer is
    # injected): the write fails, and so does the clean-up's unlink.
    monkeypatch.setattr(pathlib.Path, "unlink", read_only)
    with pytest.raises(SystemExit) as stop:
        with files.replacing(tmp_path / "phases.png"):
            read_only()
    assert str(stop.value) == f"cannot write '{tmp_path / 'phases.png'}': {os.strerror(errno.EROFS)}"
