"""Running a computation that cannot be interrupted (sympy) under a time and memory budget.

:func:`run_with_budget` forks a worker process, caps its address space (``resource.RLIMIT_AS``)
at the parent's current size plus ``memory`` bytes, and waits at most ``timeout`` seconds for its
answer; on expiry the worker is killed (SIGKILL) and reaped.  The worker returns JSON text over a
pipe, never a pickle, so the parent reads data, not objects.  The parent's copy-on-write pages
are shared, so a fork costs milliseconds (a fresh interpreter would spend a second importing sympy).
"""
from __future__ import annotations

import json
import math
import multiprocessing as mp
import resource
import time
from dataclasses import dataclass
from typing import Any, Callable

from kin.errors import RmtError
from kin.validation import is_count, is_real

#: default memory the worker may add to the parent's address space (bytes)
DEFAULT_MEMORY = 1 << 30


class BudgetError(RmtError, ValueError):
    """A budget (time or memory) is not a usable number."""


@dataclass
class BudgetResult:
    """What the budgeted run gave: ``status`` ``"done"``, ``"timeout"``, ``"memory"`` or ``"error"``;
    ``value`` the decoded JSON answer when done; ``seconds`` wall time spent; ``detail`` a message."""

    status: str
    value: Any
    seconds: float
    detail: str = ""


def _address_space() -> int:
    """This process's virtual memory size (bytes), from /proc; 0 when unknown."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


def _child(conn, fn: Callable[..., Any], args: tuple, memory: int) -> None:
    try:
        limit = _address_space() + memory
        if limit > memory:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        conn.send_bytes(json.dumps({"ok": fn(*args)}).encode())
    except MemoryError:
        conn.send_bytes(b'{"memory": true}')
    except BaseException as e:  # every failure is reported to the parent as data
        try:
            conn.send_bytes(json.dumps({"error": f"{type(e).__name__}: {e}"[:500]}).encode())
        except BaseException:
            pass
    finally:
        conn.close()


def check_budget(timeout: float, memory: int) -> None:
    """Raise :class:`BudgetError` unless 0 ≤ timeout ≤ 3600 s and 1 MiB ≤ memory ≤ 1 TiB."""
    if not is_real(timeout) or not (0 <= timeout <= 3600) \
            or not math.isfinite(timeout):
        raise BudgetError(f"exact_timeout (--exact-timeout) {timeout!r} must be a number of seconds in [0, 3600]")
    if not is_count(memory) or not ((1 << 20) <= memory <= (1 << 40)):
        raise BudgetError(f"exact_memory {memory!r} must be an integer number of bytes in [2^20, 2^40]")


def run_with_budget(fn: Callable[..., Any], args: tuple = (), timeout: float = 5.0,
                    memory: int = DEFAULT_MEMORY, on_wait: Callable[[float], None] | None = None) -> BudgetResult:
    """Run ``fn(*args)`` (its result must be JSON-serialisable) in a forked worker within
    ``timeout`` seconds and ``memory`` bytes more than this process holds now.  ``on_wait`` is
    called with the seconds elapsed about every 0.2 s while waiting."""
    check_budget(timeout, memory)
    t0 = time.perf_counter()
    if timeout == 0:
        return BudgetResult("timeout", None, 0.0, "no time given")
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(child, fn, args, memory), daemon=True)
    proc.start()
    child.close()
    try:
        ready = False
        while not ready:
            left = timeout - (time.perf_counter() - t0)
            if left <= 0:
                break
            ready = parent.poll(min(left, 0.2))
            if on_wait is not None:
                on_wait(time.perf_counter() - t0)
        if not ready:
            return BudgetResult("timeout", None, time.perf_counter() - t0, f"no answer within {timeout:g} s")
        try:
            msg = json.loads(parent.recv_bytes().decode())
        except (EOFError, OSError, ValueError, UnicodeDecodeError):
            # the worker died without answering: the memory cap makes the allocator fail hard
            return BudgetResult("memory", None, time.perf_counter() - t0, "the worker ended without an answer")
    finally:
        if proc.is_alive():
            proc.kill()
        proc.join(5)
        parent.close()
    dt = time.perf_counter() - t0
    if "ok" in msg:
        return BudgetResult("done", msg["ok"], dt)
    if msg.get("memory"):
        return BudgetResult("memory", None, dt, f"more than {memory / 2**20:.0f} MiB needed")
    return BudgetResult("error", None, dt, str(msg.get("error", "unknown failure")))
