"""Writing output files without damaging what is there: every file rmtkit writes goes through here.

:func:`write_output` writes one file:

* it refuses to replace anything that is not a regular file — a symbolic link, a directory, a
  FIFO, a device node or a socket — with an :class:`OutputError` naming the path;
* missing parent directories are **created** (as ``mkdir -p`` would); a parent that exists but
  is not a directory is an error;
* the data go to a temporary file in the target's own directory (``.NAME.XXXX.tmp``), which is
  renamed over the target only when complete (the rename is atomic on one file system), and is
  removed when anything fails — so the target holds either its old or its whole new content.

:func:`check_output` runs the same checks up front (commands call it before a long computation).
:func:`fresh_directory` does the same for a whole run directory: everything is written into a new
hidden directory beside it, which replaces the old one only when the run completes.
"""
from __future__ import annotations

import os
import shutil
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO, Callable, Collection, Iterator

from kin.errors import RmtError

__all__ = ["OutputError", "check_output", "write_output", "fresh_directory"]


class OutputError(RmtError):
    """An output path cannot be written safely (not a regular file, parent not a directory, I/O error)."""


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def _reason(e: OSError) -> str:
    return e.strerror or type(e).__name__


def _check_parents(path: Path) -> None:
    """The nearest existing ancestor of ``path`` must be a directory."""
    parent = path.parent
    while True:
        try:
            pst = os.stat(parent)
        except (FileNotFoundError, NotADirectoryError):
            if parent.parent == parent:
                return
            parent = parent.parent
            continue
        except OSError as e:
            raise OutputError(f"{path}: cannot be written ({parent}: {_reason(e)})") from None
        if not stat.S_ISDIR(pst.st_mode):
            raise OutputError(f"{path}: {parent} is not a directory")
        return


def check_output(path: str | os.PathLike) -> Path:
    """Raise :class:`OutputError` unless ``path`` may be written by :func:`write_output`: it must not
    exist or be a regular file, and its nearest existing ancestor must be a directory."""
    if os.fspath(path).endswith(("/", os.sep)):
        raise OutputError(f"{os.fspath(path)}: names a directory; give a file name")
    path = Path(path)
    if not path.name or path.name in (".", ".."):
        raise OutputError(f"{path}: is a directory; give a file name")
    try:
        st = os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        st = None                               # (a parent that is not a directory is named below)
    except OSError as e:
        raise OutputError(f"{path}: cannot be written ({_reason(e)})") from None
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise OutputError(f"{path}: is {_kind(st.st_mode)}; refusing to replace it (only regular files are replaced)")
    _check_parents(path)
    return path


def write_output(path: str | os.PathLike, data: str | bytes | Callable[[BinaryIO], None]) -> Path:
    """Write ``data`` (text as UTF-8, bytes, or a function that writes to a binary file) to ``path``
    safely; see the module docstring.  Returns the path."""
    path = check_output(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise OutputError(f"{path}: cannot create its directory ({_reason(e)})") from None
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as e:
        raise OutputError(f"{path}: cannot be written ({_reason(e)})") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            if callable(data):
                data(fh)
            else:
                fh.write(data.encode("utf-8") if isinstance(data, str) else data)
        os.chmod(tmp, 0o666 & ~_umask())       # mkstemp makes 0600; give the file the usual permissions
        check_output(path)                      # the target may have changed while we wrote
        os.replace(tmp, path)
    except BaseException as e:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(e, OSError):
            raise OutputError(f"{path}: cannot be written ({_reason(e)})") from None
        raise
    return path


@contextmanager
def fresh_directory(path: str | os.PathLike, replaceable: Collection[str] = ()) -> Iterator[Path]:
    """A new, empty directory to write a whole run into; it replaces ``path`` when the ``with``
    block completes, and is removed when the block fails or is interrupted (so an interrupted run
    never leaves new files beside old ones).

    An existing ``path`` must be a directory (not a symbolic link) holding only entries named in
    ``replaceable`` — the files a previous run wrote — else :class:`OutputError` is raised before
    anything is written: a run never deletes files it did not write.
    """
    path = Path(path)
    try:
        st = os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        st = None
    if st is not None:
        if not stat.S_ISDIR(st.st_mode):
            raise OutputError(f"{path}: is {_kind(st.st_mode)}; the run directory must be a directory")
        foreign = sorted(set(os.listdir(path)) - set(replaceable))
        if foreign:
            raise OutputError(f"{path}: holds {foreign[0]!r}, which a run did not write; refusing to replace the "
                              "directory (move it away or choose another --out)")
    _check_parents(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp"))
        os.chmod(tmp, 0o777 & ~_umask())     # mkdtemp makes 0700; give the directory the usual permissions
    except OSError as e:
        raise OutputError(f"{path}: cannot create the run directory ({_reason(e)})") from None
    try:
        yield tmp
        old = None
        if os.path.lexists(path):
            old = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".old"))
            os.replace(path, old / "run")
        try:
            os.replace(tmp, path)
        except OSError:
            if old is not None:
                os.replace(old / "run", path)      # put the previous run back
            raise
        finally:
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
    except BaseException as e:
        shutil.rmtree(tmp, ignore_errors=True)
        if isinstance(e, OSError):
            raise OutputError(f"{path}: cannot move the run into place ({_reason(e)})") from None
        raise
