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


def _start(sweep, db, resume):
    cmd = [sys.executable, "-m", "studies.cli", "sweep", str(sweep), "--db", str(db), "--quiet", "--workers", "1"]
    return subprocess.Popen(cmd + (["--resume"] if resume else []), cwd=ROOT, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _kill_when(proc, db, done_at_least, extra_delay):
    """SIGKILL the sweep's process group once ``done_at_least`` rows are done, after ``extra_delay`` s."""
    t0 = time.monotonic()
    while _done(db) < done_at_least and proc.poll() is None and time.monotonic() - t0 < 60:
        time.sleep(0.02)
    time.sleep(extra_delay)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)


def test_sweep_survives_kill_9_three_times(tmp_path):
    sweep = write_sweep(tmp_path, counts=(6, 6))
    db = tmp_path / "k.sqlite"
    total = 36
    rng = np.random.default_rng(11)
    # moments: while starting up (nothing committed yet), early in the run, late in the run
    for i, (at, delay) in enumerate([(0, rng.uniform(0.5, 1.5)), (6, rng.uniform(0, 0.3)),
                                     (20, rng.uniform(0, 0.3))]):
        proc = _start(sweep, db, resume=i > 0)
        _kill_when(proc, db, at, delay)
        assert proc.returncode == -signal.SIGKILL
    assert _done(db) < total                                   # the kills came before the end
    proc = _start(sweep, db, resume=True)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err.decode()
    meta, rows = read_sweep(db)
    keys = [r["key"] for r in rows]
    sw = load_sweep(sweep)
    assert len(keys) == len(set(keys)) == total
    assert set(keys) == {d.key for d in sample_designs(sw)}
    assert all(r["status"] == "done" for r in rows)
    job = make_job(sw)
    for r in rows:
        d = Design.make(r["architecture"], r["params"])
        assert r["metrics"] == evaluate_design(job, job_robot(job, d.architecture), d), r["key"]
