"""Several learned-window trainings at once: how a learned window depends on its training size and seed.

Each run (``n_train``, ``seed``) trains one network and evaluates every factor
(:func:`design.learned.windows.learned_windows`); a run is single-threaded (the networks train on one
BLAS thread, see :data:`design.learned.ik.BLAS_THREADS`) and independent of the others, so the runs
are spread over worker processes — one per CPU this process may use (``RMTKIT_THREADS`` caps it) —
and a 2-core machine finishes a comparison in about half the time.  Every run is seeded, so the
answer does not depend on how many workers ran it: the reports are those of the same runs made one
after another, in the order given.

Workers are forked (POSIX): they inherit the robot and its singular analysis from the parent instead
of receiving them pickled.  Where fork is unavailable, or with one worker, the runs are made here.
"""
from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from typing import Callable, Sequence

from design.learned.windows import jsonable_report, learned_windows
from kin.native.settings import default_threads

__all__ = ["LearnedRuns", "learned_runs"]

#: the robot and analysis the forked workers inherit (set only while a pool runs)
_SHARED: dict = {}


def _one(run: tuple[int, int]) -> list[dict]:
    n_train, seed = run
    _, reports = learned_windows(_SHARED["robot"], analysis=_SHARED["analysis"], seed=seed, n_train=n_train,
                                 **_SHARED["kwargs"])
    return [jsonable_report(r) for r in reports]


class LearnedRuns:
    """Runs ``(n_train, seed)`` of :func:`learned_windows` started in worker processes, so that the
    caller can work meanwhile (e.g. train its main network); :meth:`results` waits for them.  Use it
    as a context manager (the workers stop on leaving it).  See :func:`learned_runs`."""

    def __init__(self, robot, analysis, runs: Sequence[tuple[int, int]], workers: int | None = None, **kwargs):
        self.runs = [(int(n), int(s)) for n, s in runs]
        self.workers = min(len(self.runs), default_threads() if workers is None else max(1, int(workers)))
        self._pool = None
        self._futures = []
        _SHARED.update(robot=robot, analysis=analysis, kwargs=kwargs)
        if self.workers > 1 and "fork" in multiprocessing.get_all_start_methods():
            self._pool = ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("fork"))
            self._futures = [self._pool.submit(_one, r) for r in self.runs]

    def results(self, progress: Callable[[str], None] | None = None) -> list[list[dict]]:
        """The factor reports of each run, in the order given (made here when no worker runs them)."""
        out = []
        for k, (n, s) in enumerate(self.runs):
            out.append(self._futures[k].result() if self._pool is not None else _one((n, s)))
            if progress:
                progress(f"training run: {n:,} poses, seed {s}")
        return out

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        _SHARED.clear()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def learned_runs(robot, analysis, runs: Sequence[tuple[int, int]], workers: int | None = None,
                 progress: Callable[[str], None] | None = None, **kwargs) -> list[list[dict]]:
    """The factor reports (as :func:`jsonable_report` gives them) of each run ``(n_train, seed)`` of
    :func:`learned_windows` on ``robot`` with ``analysis``, in the order of ``runs``.

    ``workers``: processes (default: the CPUs this process may use, at most one per run);
    ``progress``: called with one line as each run finishes; ``kwargs``: passed on to
    :func:`learned_windows` (``n_eval``, ``branch``)."""
    with LearnedRuns(robot, analysis, runs, workers, **kwargs) as pending:
        return pending.results(progress)
