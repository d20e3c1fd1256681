"""The one threading model: POSIX threads per call, no OpenMP runtime — so neither ``import kin``
nor a multi-threaded FK or IK batch changes an environment variable or loads libgomp."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from kin.native import find_compiler

ROOT = Path(__file__).resolve().parents[3]

_SCRIPT = textwrap.dedent("""
    import json, os
    before = dict(os.environ)
    import kin
    after_import = dict(os.environ)
    robot = kin.load_robot("puma560")
    Q = robot.random_configurations(20_000, seed=0)
    robot.evaluator.threads = 2
    T = robot.fk(Q)
    res = robot.ik(T[:64], seed=0, threads=2)
    after_batches = dict(os.environ)
    with open("/proc/self/maps") as f:
        gomp = "libgomp" in f.read()
    changed = lambda a, b: sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
    print(json.dumps({"import": changed(before, after_import), "batches": changed(before, after_batches),
                      "gomp": gomp, "backend": robot.backend, "solved": int(res.success.sum()),
                      "threads": robot.evaluator.last_threads}))
""")


@pytest.mark.skipif(find_compiler() is None or not Path("/proc/self/maps").exists(),
                    reason="needs a C compiler and /proc")
def test_import_and_batches_leave_the_environment_alone():
    env = {k: v for k, v in os.environ.items() if not k.startswith("OMP_")}
    env["PYTHONPATH"] = str(ROOT)
    proc = subprocess.run([sys.executable, "-c", _SCRIPT], env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["import"] == [] and out["batches"] == []
    assert out["backend"] == "compiled" and out["solved"] == 64 and out["threads"] == 2
    assert not out["gomp"]  # no OpenMP runtime in the process
