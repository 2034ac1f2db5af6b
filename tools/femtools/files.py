"""Results written whole or not at all, as the C++ programs write theirs (common/atomic_file.hpp)."""
import contextlib
import errno
import os
import pathlib
import sys


@contextlib.contextmanager
def replacing(path):
    """Results written whole or not at all, as the C++ programs write theirs
    (common/atomic_file.hpp): the body writes the temporary path this yields (hidden, in the
    same folder, with the same suffix, so that matplotlib and Pillow see the format); it is
    flushed to the disk and renamed over `path`. A failure ends the script with the path and
    the cause (exit 1) and leaves the earlier file as it was. FEM_FAIL_WRITES=NAME (or "*")
    injects a full disk into the write of a file named NAME, as in the C++ programs.

        with replacing(out / "phases.png") as tmp:
            fig.savefig(tmp, dpi=130)
    """
    path = pathlib.Path(path)
    tmp = path.with_name(f".{path.stem}.tmp{os.getpid()}{path.suffix}")
    if path.exists() and not path.is_file():  # a device, a FIFO, a folder: the rename would replace it
        sys.exit(f"cannot write '{path}': it is not a regular file (a device, a FIFO or a folder); "
                 "give a file's path")
    try:
        yield tmp
        if os.environ.get("FEM_FAIL_WRITES") in ("*", path.name):
            os.truncate(tmp, os.path.getsize(tmp) // 2)
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError as e:
        remove_quietly(tmp)
        sys.exit(f"cannot write '{path}': {e.strerror or e}")
    except BaseException:
        remove_quietly(tmp)
        raise


def remove_quietly(tmp):
    """The temporary file removed where it can be: on a read-only folder the removal fails as
    the write did, and the write's cause is the one to report (not a second traceback)."""
    try:
        tmp.unlink(missing_ok=True)
    except OSError:
        pass


def write_text(path, text):
    """path.write_text(text), whole or not at all (replacing)."""
    with replacing(path) as tmp:
        tmp.write_text(text)
