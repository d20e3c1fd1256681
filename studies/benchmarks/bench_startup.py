"""Start-up benchmark: how long a user waits for a whole ``rmt plan`` / ``rmt check-path`` process.

Run as ``python -m studies.benchmarks.bench_startup [--json] [--runs N]`` (part of ``make bench``).
Each command runs as a fresh process (``sys.executable -m studies.cli …``) on the FANUC M-16iB/20
with windows from ``--margin 0.05``; one warm-up run fills the on-disk caches (compiled evaluators,
the exact singular analysis, the built windows), then ``--runs`` counted runs give the median
wall time.  The commands:

* ``plan`` of a query the wrist window separates (answered before any planning: the verdict is
  what the user waits for);
* ``plan`` of a query that needs planning around the shoulder window;
* ``check-path`` of the path the previous command wrote;
* ``plan --cell`` of the README's move in the bundled weld cell (the LR Mate 200iD, windows and
  collisions, every motion proven: the cell's enclosures come from the on-disk cache when warm).

For scale, the same run times a bare ``python -c "import numpy"`` and, when the ``bench`` extra is
installed, the peer roboticstoolbox-python loading its Puma 560 model and answering one manipulability
query in a fresh process (``rtb.models.DH.Puma560()``, as its docs show).

Targets (PASS/MISS): a warm separated ``rmt plan`` ≤ 0.5 s median, and a warm ``rmt plan --cell``
≤ 0.5 s median.  A MISS does not change the exit status (0); an error does.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

START = ["0", "-0.3", "0.4", "0.2", "-0.6", "0"]
SEPARATED_GOAL = ["0.4", "-0.2", "0.3", "-0.2", "0.8", "0.1"]
AROUND = (["2.4108", "0.4729", "2.6727", "-1.9392", "1.5042", "1.629"],
          ["1.892", "2.4863", "4.5218", "-1.6025", "1.4925", "4.7867"])
CELL_MOVE = (["0", "0", "0", "0", "-90", "0"], ["40", "20", "-10", "0", "-80", "0"])
TARGET_S = 0.5
#: the figures with a target
TARGETS = ("rmt plan (separated query)", "rmt plan --cell (the weld cell)")
PEER = ("import roboticstoolbox as rtb; import numpy as np; robot = rtb.models.DH.Puma560(); "
        "robot.manipulability(np.zeros(6))")


#: the processes' environment: warm as on a user's install, so Python's bytecode cache is written and
#: read (a shell with PYTHONDONTWRITEBYTECODE set would recompile every module of every run)
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def _time(argv: list[str], runs: int, ok=(0,)) -> list[float]:
    out = []
    for k in range(runs + 1):                 # the first run is the warm-up
        t0 = time.perf_counter()
        p = subprocess.run(argv, capture_output=True, text=True, env=ENV)
        dt = time.perf_counter() - t0
        if p.returncode not in ok:
            raise RuntimeError(f"{' '.join(argv)} exited {p.returncode}: {p.stderr.strip()[-400:]}")
        if k:
            out.append(dt)
    return out


def run(runs: int) -> dict:
    rmt = [sys.executable, "-m", "studies.cli"]
    rows = {}
    with tempfile.TemporaryDirectory(prefix="rmt-bench-") as tmp:
        path = Path(tmp) / "around.csv"
        rows["rmt plan (separated query)"] = _time(
            [*rmt, "plan", "fanuc_m16ib20", "--start", *START, "--goal", *SEPARATED_GOAL, "--margin", "0.05",
             "--json"], runs, ok=(1,))
        rows["rmt plan (around the shoulder window)"] = _time(
            [*rmt, "plan", "fanuc_m16ib20", "--start", *AROUND[0], "--goal", *AROUND[1], "--margin", "0.05",
             "--out", str(path), "--json"], runs)
        rows["rmt check-path (that path)"] = _time(
            [*rmt, "check-path", "fanuc_m16ib20", str(path), "--margin", "0.05", "--json"], runs)
        rows["rmt plan --cell (the weld cell)"] = _time(
            [*rmt, "plan", "fanuc_lrmate200id", "--start", *CELL_MOVE[0], "--goal", *CELL_MOVE[1], "--margin", "3",
             "--cell", "fanuc_weld_cell", "--out", str(Path(tmp) / "weld.csv"), "--json"], runs)
    rows["python -c 'import numpy' (floor)"] = _time([sys.executable, "-c", "import numpy"], runs)
    if importlib.util.find_spec("roboticstoolbox") is not None:
        rows["peer: roboticstoolbox Puma560 + one query"] = _time([sys.executable, "-c", PEER], runs)
    return {name: {"median_s": statistics.median(t), "min_s": min(t), "max_s": max(t), "runs": len(t)}
            for name, t in rows.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="bench_startup", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--runs", type=int, default=5, help="counted runs per command (default 5)")
    args = ap.parse_args(argv)
    res = run(max(1, args.runs))
    verdicts = {name: "PASS" if res[name]["median_s"] <= TARGET_S else "MISS" for name in TARGETS}
    verdict = "MISS" if "MISS" in verdicts.values() else "PASS"
    peer = res.get("peer: roboticstoolbox Puma560 + one query")
    if args.json:
        print(json.dumps({"results": res, "target_s": TARGET_S, "verdicts": verdicts, "verdict": verdict}))
        return 0
    print(f"whole-process wall time, median of {args.runs} warm runs (min–max)")
    for name, r in res.items():
        ratio = f"   {r['median_s'] / peer['median_s']:.2f}× the peer" if peer and not name.startswith("peer") \
            and not name.startswith("python") else ""
        print(f"  {name:<42} {r['median_s']:.3f} s  ({r['min_s']:.3f}–{r['max_s']:.3f}){ratio}")
    for name, v in verdicts.items():
        print(f"{v}: warm {name} {res[name]['median_s']:.3f} s (target ≤ {TARGET_S:g} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
