"""Running a sweep: the driver.  It samples the designs, opens the store, has the pending designs
evaluated (:mod:`design.sweep.dispatch`), optionally refines (:mod:`design.sweep.refine`), and
reports.  The run stops submitting when ``max_time`` has passed; the rows not reached stay
``pending`` for ``resume``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from design.sweep.dispatch import evaluate_pending
from design.sweep.evaluate import SweepJob, job_fingerprint, make_job, warm_cache
from design.sweep.file import Sweep, SweepError
from design.sweep.space import sample_designs
from design.sweep.store import Store

__all__ = ["SweepReport", "run_sweep", "sweep_meta"]


@dataclass
class SweepReport:
    """What a run did: rows per status at the end (``counts``), designs evaluated in this run
    (``evaluated``, of which ``failed_now`` failed), ``added`` new rows, ``reset`` running rows of
    a dead run put back to pending, ``retried`` failed rows retried, wall ``time_s``, the executor's
    name, whether the budget stopped it, and the refinement's report (or None)."""

    name: str
    db: str
    counts: dict
    evaluated: int
    failed_now: int
    added: int
    reset: int
    retried: int
    time_s: float
    executor: str
    stopped_by_budget: bool = False
    refine: dict | None = None
    best: dict | None = field(default=None)

    @property
    def rate(self) -> float:
        """Designs evaluated per second of this run."""
        return self.evaluated / self.time_s if self.time_s > 0 else 0.0

    def to_dict(self) -> dict:
        return {"name": self.name, "db": self.db, "counts": self.counts, "evaluated": self.evaluated,
                "failed_now": self.failed_now, "added": self.added, "reset_running": self.reset,
                "retried_failed": self.retried, "time_s": self.time_s, "designs_per_s": self.rate,
                "executor": self.executor, "stopped_by_budget": self.stopped_by_budget, "best": self.best,
                "refine": self.refine}


def sweep_meta(sweep: Sweep, job: SweepJob) -> dict:
    """The sweep's description stored in the database's meta table."""
    chain = sweep.task.robot.chain
    units = {k: chain.length_unit if p.kind == "length" else chain.angle_unit for k, p in chain.parameters.items()}
    scales = {k: chain.length_scale if p.kind == "length" else chain.angle_scale for k, p in chain.parameters.items()}
    return {"application": "rmtkit-sweep", "name": sweep.name, "fingerprint": job_fingerprint(job),
            "robot": chain.name, "task": sweep.task.name, "parameters": list(chain.parameters),
            "swept": [ps.name for ps in sweep.parameters], "units": units, "scales": scales,
            "bounds": {k: list(p.bounds) for k, p in chain.parameters.items()},
            "objective": sweep.task.objective, "min_coverage": sweep.task.min_coverage,
            "metrics": list(sweep.metrics), "sampling": sweep.sampling, "seed": sweep.seed,
            "evaluation": {"seeds": sweep.seeds, "samples": sweep.samples, "seed": sweep.eval_seed}}


def run_sweep(sweep: Sweep, db: str | Path, executor=None, resume: bool = False, retry_failed: bool = False,
              refine: int = 0, progress: Callable | None = None, start: Callable | None = None,
              evaluate: Callable | None = None, max_time: float = 86_400.0, chunk_seconds: float = 0.1,
              refine_seed: int = 0) -> SweepReport:
    """Run (or resume) a sweep into the database ``db``.

    ``executor``: :class:`design.sweep.LocalExecutor` (default, one worker) or
    :class:`design.sweep.DaskExecutor`.  ``resume``: continue an existing database (done rows are
    never recomputed, running rows of a dead run go back to pending); ``retry_failed``: failed rows
    are evaluated again.  ``refine``: K designs proposed by a Gaussian-process surrogate after the
    sample (:mod:`design.sweep.refine`).  ``start(total, already_done)`` is called once the work is
    known, ``progress(n, failed)`` after every chunk.  ``evaluate`` replaces the per-design function
    (module-level, picklable).  ``max_time`` (s) bounds the run.
    """
    from design.sweep.local import LocalExecutor
    if not (0 < max_time <= 30 * 86_400):
        raise SweepError(f"max_time {max_time} s must be in (0, 30 days]")
    if not (0 <= refine <= 10_000):
        raise SweepError(f"refine {refine} must be in [0, 10000]")
    t0 = time.monotonic()
    deadline = t0 + max_time
    executor = executor or LocalExecutor(1)
    if evaluate is None and sweep.placement:
        from design.place.codesign import evaluate_placed_design
        evaluate = evaluate_placed_design
    job = make_job(sweep, evaluate)
    with Store(db, sweep_meta(sweep, job), resume=resume) as store:
        reset = store.reset_running()
        retried = store.retry_failed() if retry_failed else 0
        added = store.add(sample_designs(sweep), sweep.eval_seed)
        pending = store.designs(["pending"])
        counts = store.counts()
        if start:
            start(len(pending) + refine, counts["done"] + counts["failed"])
        evaluated = failed = 0
        stopped = False
        refine_report = None
        warm_cache(job, sorted({d.architecture for d in pending} | set(sweep.architectures)))
        executor.open(job)
        try:
            evaluated, failed, stopped = evaluate_pending(store, executor, pending, progress, chunk_seconds, deadline)
            if refine and not stopped:
                from design.sweep.refine import refine_sweep
                refine_report = refine_sweep(store, sweep, executor, refine, progress=progress, seed=refine_seed,
                                             deadline=deadline)
                evaluated += refine_report["evaluated"]
                failed += refine_report["failed"]
        finally:
            executor.close()
        counts = store.counts()
        from design.sweep.export import best_row
        best = best_row(store.rows(), sweep.task.objective)
    return SweepReport(sweep.name, str(db), counts, evaluated, failed, added, reset, retried,
                       time.monotonic() - t0, executor.name, stopped, refine_report, best)
