"""Local worker processes: ``concurrent.futures.ProcessPoolExecutor`` with the spawn start method.

Each worker receives the job once (the pool's initializer), builds its robots once, and loads
their compiled evaluators from the on-disk cache the driver filled.  Workers run with one compute
thread (``RMTKIT_THREADS`` and ``OMP_NUM_THREADS`` = 1 in their environment, by default):
several processes each spinning up all-core OpenMP slow each other down by an order of magnitude.

A worker process that dies (killed, out of memory, a crash in native code) breaks the pool: the
pool is restarted and every chunk in flight is resubmitted; a chunk that has lost its worker
``max_tries`` times is stored as failed.
"""
from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from typing import Callable, Iterator

from design.sweep.evaluate import Outcome, SweepJob
from design.sweep.space import Design
from kin.errors import ArgumentError

__all__ = ["LocalExecutor", "thread_environment", "lost_chunk"]

_THREAD_VARS = ("RMTKIT_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


@contextmanager
def thread_environment(threads: int):
    """``os.environ`` with the compute-thread variables set to ``threads`` (restored afterwards);
    spawned workers inherit it."""
    old = {k: os.environ.get(k) for k in _THREAD_VARS}
    os.environ.update({k: str(threads) for k in _THREAD_VARS})
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def lost_chunk(chunk: list[Design], tries: int) -> list[Outcome]:
    """Failed outcomes for a chunk whose worker died ``tries`` times."""
    return [Outcome(d.key, False, None, f"WorkerLost: the worker evaluating this design died {tries} times", 0.0, "")
            for d in chunk]


_JOB: SweepJob | None = None


def _init(job: SweepJob, threads: int) -> None:
    global _JOB
    os.environ.update({k: str(threads) for k in _THREAD_VARS})
    _JOB = job


def _run(chunk: list[Design]) -> list[Outcome]:
    return _JOB.run_chunk(chunk)


class LocalExecutor:
    """``workers`` local processes (start method ``spawn`` or ``forkserver``), ``threads`` compute
    threads each, at most ``in_flight`` chunks per worker queued."""

    def __init__(self, workers: int = 1, threads: int = 1, start_method: str = "spawn", in_flight: int = 2,
                 max_tries: int = 3):
        if start_method not in ("spawn", "forkserver"):
            raise ArgumentError(f"start method {start_method!r} unknown; allowed: spawn, forkserver")
        self.workers, self.threads, self.start_method = workers, threads, start_method
        self.in_flight, self.max_tries = in_flight, max_tries

    @property
    def name(self) -> str:
        return f"local:{self.workers}"

    def _pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context(self.start_method),
                                   initializer=_init, initargs=(self._job, self.threads))

    def open(self, job: SweepJob) -> None:
        """Start the pool for ``job`` (workers spawn on demand, with the one-thread environment)."""
        self._env = thread_environment(self.threads)
        self._env.__enter__()
        self._job = job
        self._p = self._pool()

    def close(self) -> None:
        """Stop the workers (waits for the chunks they are running)."""
        if getattr(self, "_p", None) is not None:
            self._p.shutdown(wait=True, cancel_futures=True)
            self._p = None
            self._env.__exit__(None, None, None)

    def run(self, next_chunk: Callable[[], list[Design] | None],
            on_submit: Callable[[list[Design]], None]) -> Iterator[list[Outcome]]:
        """Evaluate the chunks ``next_chunk`` gives (None: no more) and yield each chunk's outcomes
        as it completes; ``on_submit`` is called with every chunk sent out.  Needs :meth:`open`."""
        flight: dict = {}
        retry: list[tuple[list[Design], int]] = []
        exhausted = False
        try:
            while True:
                while len(flight) < self.in_flight * self.workers and (retry or not exhausted):
                    if retry:
                        chunk, tries = retry.pop()
                    else:
                        chunk, tries = next_chunk(), 0
                        if chunk is None:
                            exhausted = True
                            break
                        on_submit(chunk)
                    flight[self._p.submit(_run, chunk)] = (chunk, tries)
                if not flight:
                    return
                done, _ = wait(flight, return_when=FIRST_COMPLETED)
                broken = False
                for f in done:
                    chunk, tries = flight.pop(f)
                    try:
                        out = f.result()
                    except BrokenProcessPool:
                        broken = True
                        retry.append((chunk, tries + 1))
                        continue
                    yield out
                if broken:             # every chunk still in flight is lost with the pool
                    retry.extend((c, t + 1) for c, t in flight.values())
                    flight.clear()
                    self._p.shutdown(wait=True, cancel_futures=True)
                    for c, t in [x for x in retry if x[1] >= self.max_tries]:
                        yield lost_chunk(c, t)
                    retry = [x for x in retry if x[1] < self.max_tries]
                    self._p = self._pool()
        finally:
            for f in flight:
                f.cancel()
