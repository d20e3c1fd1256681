"""An exclusive lock between processes (and threads), held on a lock file: ``fcntl.flock``.

The lock belongs to the open file description, so two processes — or two threads of one process —
that open the same lock file exclude each other, and a process that dies releases its lock.  The
holder removes the file before releasing it, so a cache directory keeps no lock files; a waiter
that opened the removed file then still gets the lock, while a newcomer may lock a new file at
the same path — so the guarded work must be idempotent: "build the library unless it exists",
re-checked under the lock, is (at worst a failed build is retried by both).  Where ``fcntl`` does
not exist (Windows) the lock is a no-op and builds rely on the atomic rename alone.
"""
from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterator
from pathlib import Path

from kin.errors import CompileError

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None


@contextlib.contextmanager
def file_lock(path: Path, timeout: float, what: str) -> Iterator[None]:
    """Hold the lock ``path`` (created when missing) for the ``with`` block; after ``timeout``
    seconds of waiting for another holder, :class:`~kin.errors.CompileError`."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if fcntl is not None:
            deadline = time.monotonic() + timeout
            delay = 0.005
            while True:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    if time.monotonic() > deadline:
                        raise CompileError(f"waited {timeout:.0f} s for another process building {what} "
                                           f"(lock {path})") from None
                    time.sleep(delay)
                    delay = min(2 * delay, 0.2)
        yield
    finally:
        try:
            os.unlink(path)
        except OSError:
            pass
        os.close(fd)  # releases the lock
