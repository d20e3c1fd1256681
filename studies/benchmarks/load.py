"""Machine load around a benchmark: how much CPU other processes took, and a bounded busy process.

The benchmarks run on shared machines.  :class:`ForeignLoad` measures, for a block of code, the CPU
time every *other* process used meanwhile (Linux ``/proc/stat`` busy ticks minus this process's and
its waited-for children's CPU time), as a share of the whole machine; a figure measured while that
share is above :data:`UNRELIABLE_SHARE` is flagged unreliable.  Elsewhere it falls back to the
1-minute load average.  :func:`busy_process` starts one spinning Python process that stops by itself
after a time bound (the "loaded" case of the kinematics benchmark).
"""
from __future__ import annotations

import os
import subprocess
import sys
import time

UNRELIABLE_SHARE = 0.10  # other processes used more than 10 % of the machine's CPU time


def _busy_ticks() -> int | None:
    try:
        with open("/proc/stat") as f:
            fields = f.readline().split()
    except OSError:
        return None
    if not fields or fields[0] != "cpu":
        return None
    v = [int(x) for x in fields[1:9]]  # user nice system idle iowait irq softirq steal
    return v[0] + v[1] + v[2] + v[5] + v[6] + v[7]


def _own_cpu_s() -> float:
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


class ForeignLoad:
    """Context manager: ``share`` = CPU time of other processes / (wall time × CPUs) while inside.

    ``reliable`` is False when that share exceeds :data:`UNRELIABLE_SHARE` (or, without
    ``/proc/stat``, when the 1-minute load average exceeds 0.5 per CPU).
    """

    def __enter__(self) -> "ForeignLoad":
        self.loadavg_before = os.getloadavg()[0]
        self._t0, self._busy0, self._own0 = time.perf_counter(), _busy_ticks(), _own_cpu_s()
        return self

    def __exit__(self, *exc) -> None:
        wall = max(time.perf_counter() - self._t0, 1e-9)
        busy1, own1 = _busy_ticks(), _own_cpu_s()
        ncpu = os.cpu_count() or 1
        self.loadavg_after = os.getloadavg()[0]
        if self._busy0 is None or busy1 is None:
            self.share = None
            self.reliable = max(self.loadavg_before, self.loadavg_after) <= 0.5 * ncpu
            return
        hz = os.sysconf("SC_CLK_TCK")
        foreign = (busy1 - self._busy0) / hz - (own1 - self._own0)
        self.share = max(0.0, foreign / (wall * ncpu))
        self.reliable = self.share <= UNRELIABLE_SHARE

    def as_dict(self) -> dict:
        return {"foreign_cpu_share": self.share, "reliable": self.reliable,
                "loadavg_1min_before": self.loadavg_before, "loadavg_1min_after": self.loadavg_after}


_SPIN = "import time\nend = time.monotonic() + {s}\nwhile time.monotonic() < end:\n    pass\n"


def busy_process(seconds: float) -> subprocess.Popen:
    """One Python process spinning on a CPU for at most ``seconds`` (it exits by itself); the caller
    may stop it earlier with ``terminate()`` and must ``wait()`` for it."""
    if not 0 < seconds <= 600:
        raise ValueError(f"busy process bound {seconds} s; allowed: (0, 600]")
    return subprocess.Popen([sys.executable, "-c", _SPIN.format(s=float(seconds))], stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
