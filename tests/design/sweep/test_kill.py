"""A sweep process killed with SIGKILL at three different moments and resumed each time ends with
every design stored exactly once, all done, and every done row equal to a fresh in-process
evaluation of its design."""
import os
import signal
import sqlite3
import subprocess
import sys
import time

import numpy as np

from design.sweep import load_sweep, read_sweep, sample_designs
from design.sweep.evaluate import evaluate_design, job_robot, make_job
from design.sweep.space import Design
from tests.design.sweep.helpers import ROOT, write_sweep


def _done(db) -> int:
    try:
        con = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=1)
        try:
            return con.execute("SELECT COUNT(*) FROM designs WHERE status = 'done'").fetchone()[0]
        finally:
            con.close()
    except sqlite3.Error:
        return 0


#: the sweep process: run_sweep with one worker process and the 20 ms-per-design evaluation
DRIVER = """
import sys
from design.sweep import LocalExecutor, load_sweep, run_sweep
from tests.design.sweep.helpers import evaluate_slow
rep = run_sweep(load_sweep(sys.argv[1]), sys.argv[2], LocalExecutor(1), resume=sys.argv[3] == "1",
                evaluate=evaluate_slow)
sys.exit(0 if rep.counts["done"] == 100 else 1)
"""


def _start(sweep, db, resume):
    return subprocess.Popen([sys.executable, "-c", DRIVER, str(sweep), str(db), "1" if resume else "0"], cwd=ROOT,
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _kill_when(proc, db, done_at_least, extra_delay):
    """SIGKILL the sweep's process group once ``done_at_least`` rows are done, after ``extra_delay`` s."""
    t0 = time.monotonic()
    while _done(db) < done_at_least and proc.poll() is None and time.monotonic() - t0 < 60:
        time.sleep(0.02)
    time.sleep(extra_delay)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    return _done(db)


def test_sweep_survives_kill_9_three_times(tmp_path):
    sweep = write_sweep(tmp_path, counts=(10, 10), extra='')
    db = tmp_path / "k.sqlite"
    total = 100
    rng = np.random.default_rng(11)
    # moments: while starting up (nothing committed yet), early in the run, late in the run
    at_kill = []
    for i, (at, delay) in enumerate([(0, rng.uniform(0.5, 1.5)), (10, rng.uniform(0, 0.3)),
                                     (50, rng.uniform(0, 0.3))]):
        proc = _start(sweep, db, resume=i > 0)
        at_kill.append(_kill_when(proc, db, at, delay))
        assert proc.returncode == -signal.SIGKILL            # killed while running, not after it ended
    assert any(0 < n < total for n in at_kill), at_kill       # at least one kill in the middle of the work
    proc = _start(sweep, db, resume=True)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err.decode()
    meta, rows = read_sweep(db)
    keys = [r["key"] for r in rows]
    sw = load_sweep(sweep)
    assert len(keys) == len(set(keys)) == total
    assert set(keys) == {d.key for d in sample_designs(sw)}
    assert all(r["status"] == "done" for r in rows)
    job = make_job(sw)                    # the plain evaluation: evaluate_slow only waits before it
    for r in rows:
        d = Design.make(r["architecture"], r["params"])
        assert r["metrics"] == evaluate_design(job, job_robot(job, d.architecture), d), r["key"]
