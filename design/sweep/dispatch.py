"""Handing pending designs to an executor in chunks and recording every outcome in the store (the
driver is the only writer of the database).

Chunks are sized from the measured time per design to about ``chunk_seconds`` of work each (one
design to start with), which keeps a process pool's or a Dask scheduler's per-task overhead small;
the rows do not depend on the chunking, because every design is evaluated alone
(:mod:`design.sweep.evaluate`).
"""
from __future__ import annotations

import math
import time
from typing import Callable

from design.sweep.space import Design
from design.sweep.store import Store

__all__ = ["evaluate_pending"]


class _Chunks:
    """Hands out pending designs in chunks of about ``seconds`` of work."""

    def __init__(self, designs: list[Design], seconds: float, workers: int, deadline: float):
        self.designs, self.seconds, self.workers, self.deadline = designs, seconds, max(workers, 1), deadline
        self.i = 0
        self.mean = None
        self.n_obs = 0
        self.stopped = False

    def observe(self, outcomes) -> None:
        for o in outcomes:
            if o.time_s > 0:
                self.n_obs += 1
                self.mean = o.time_s if self.mean is None else self.mean + (o.time_s - self.mean) / self.n_obs

    def __call__(self) -> list[Design] | None:
        left = len(self.designs) - self.i
        if left <= 0:
            return None
        if time.monotonic() > self.deadline:
            self.stopped = True
            return None
        size = 1 if self.mean is None else max(1, min(256, math.ceil(self.seconds / max(self.mean, 1e-6))))
        size = min(size, max(1, math.ceil(left / (2 * self.workers))))    # keep every worker busy to the end
        chunk = self.designs[self.i:self.i + size]
        self.i += len(chunk)
        return chunk


def evaluate_pending(store: Store, executor, designs: list[Design], progress: Callable | None = None,
                     chunk_seconds: float = 0.1, deadline: float = math.inf) -> tuple[int, int, bool]:
    """Evaluate ``designs`` (already stored as pending) on an open executor, recording every outcome.
    Returns (evaluated, failed, stopped by the deadline)."""
    chunks = _Chunks(designs, chunk_seconds, getattr(executor, "workers", 1), deadline)
    evaluated = failed = 0
    for outcomes in executor.run(chunks, lambda c: store.mark_running(d.key for d in c)):
        store.record(outcomes)
        chunks.observe(outcomes)
        evaluated += len(outcomes)
        failed += sum(not o.ok for o in outcomes)
        if progress:
            progress(len(outcomes), sum(not o.ok for o in outcomes))
    store.flush(force=True)
    return evaluated, failed, chunks.stopped
