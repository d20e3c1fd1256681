"""Dask distributed: an existing cluster (``scheduler="tcp://HOST:PORT"``) or a ``LocalCluster``
started for the run (``local_workers=N``: N worker processes, one thread each).

The job is scattered to every worker once (and again after a worker died: a dying worker can take
the scattered key with it); designs go out in chunks (the driver sizes them to ≥ ~0.1 s of work, so
the scheduler's per-task overhead does not dominate), at most ``in_flight`` chunks per worker are
submitted at a time and results are taken with ``as_completed``, so memory stays flat however many
designs the sweep has.  A chunk whose worker died (the future errs, e.g.
``KilledWorker``) is resubmitted; after ``max_tries`` its designs are stored as failed.
"""
from __future__ import annotations

import os
from typing import Callable, Iterator

from design.sweep.evaluate import Outcome, SweepJob
from design.sweep.file import SweepError
from design.sweep.local import lost_chunk
from design.sweep.space import Design

__all__ = ["DaskExecutor"]


def _dask_chunk(job: SweepJob, chunk: list[Design], threads: int) -> list[Outcome]:
    for k in ("RMTKIT_THREADS", "OMP_NUM_THREADS"):
        os.environ[k] = str(threads)
    return job.run_chunk(chunk)


class DaskExecutor:
    """Evaluate on Dask: ``scheduler`` an address, or ``local_workers`` for a LocalCluster
    (processes, ``threads`` threads per worker, bound to 127.0.0.1)."""

    def __init__(self, scheduler: str | None = None, local_workers: int | None = None, threads: int = 1,
                 in_flight: int = 2, max_tries: int = 3, timeout: float = 60.0):
        if (scheduler is None) == (local_workers is None):
            raise SweepError("Dask: give a scheduler address or a number of local workers, not both")
        self.scheduler, self.local_workers, self.threads = scheduler, local_workers, threads
        self.in_flight, self.max_tries, self.timeout = in_flight, max_tries, timeout
        self.workers = local_workers or 0

    @property
    def name(self) -> str:
        return f"dask:{self.scheduler}" if self.scheduler else f"dask-local:{self.local_workers}"

    def _client_for_run(self):
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise SweepError("Dask executors need dask[distributed] (pip install 'rmtkit[dist]')") from None
        env = {"RMTKIT_THREADS": str(self.threads), "OMP_NUM_THREADS": str(self.threads)}
        if self.scheduler is not None:
            try:
                client = Client(self.scheduler, timeout=self.timeout)
            except (OSError, TimeoutError) as e:
                raise SweepError(f"--scheduler {self.scheduler}: cannot connect ({e})") from None
            return client, None
        cluster = LocalCluster(n_workers=self.local_workers, threads_per_worker=self.threads, processes=True,
                               host="127.0.0.1", dashboard_address=None, env=env)
        return Client(cluster), cluster

    def open(self, job: SweepJob) -> None:
        """Connect (or start the LocalCluster) and scatter the job to every worker."""
        self._client, self._cluster = self._client_for_run()
        self.workers = max(1, len(self._client.scheduler_info().get("workers", {})))
        self._job_value = job
        self._job = self._client.scatter(job, broadcast=True)

    def close(self) -> None:
        if getattr(self, "_client", None) is not None:
            self._client.close()
            if self._cluster is not None:
                self._cluster.close()
            self._client = None

    def run(self, next_chunk: Callable[[], list[Design] | None],
            on_submit: Callable[[list[Design]], None]) -> Iterator[list[Outcome]]:
        """As :meth:`design.sweep.local.LocalExecutor.run`.  Needs :meth:`open`."""
        from distributed import as_completed
        client = self._client
        flight: dict = {}
        ac = as_completed()
        exhausted = False

        def submit(chunk, tries):
            f = client.submit(_dask_chunk, self._job, chunk, self.threads, pure=False)
            flight[f.key] = (chunk, tries, f)
            ac.add(f)

        def fill():
            nonlocal exhausted
            while not exhausted and len(flight) < self.in_flight * self.workers:
                chunk = next_chunk()
                if chunk is None:
                    exhausted = True
                    return
                on_submit(chunk)
                submit(chunk, 0)
        try:
            fill()
            for f in ac:
                chunk, tries, _ = flight.pop(f.key)
                try:
                    out = f.result()
                except Exception:          # the worker died or the task was lost: resubmit
                    if tries + 1 >= self.max_tries:
                        yield lost_chunk(chunk, tries + 1)
                    else:
                        # a dying worker can take the scattered job with it (the scheduler then drops
                        # the key): scatter it again before the chunk goes out once more
                        self._job = client.scatter(self._job_value, broadcast=True)
                        submit(chunk, tries + 1)
                    fill()
                    continue
                finally:
                    f.release()
                yield out
                fill()
        finally:
            for _, _, f in flight.values():
                f.cancel()
