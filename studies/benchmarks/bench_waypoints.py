"""Through-waypoints benchmark: the cycle time of rmtkit's spline shape against TOPP-RA's typical use.

Run as ``python -m studies.benchmarks.bench_waypoints [--json] [--quick]`` (part of ``make bench``).

The waypoints: 100 joint waypoints of the FANUC M-16iB/20 (:func:`studies.benchmarks.bench_timing.fanuc_path`,
three sinusoids per joint; the bench path with 0.3–1.5 cycles, and two rougher ones with 1–3 and 2–5
cycles over the path, for transparency).  Limits v = (2.5, 2.5, 3, 5, 5, 7) rad/s and
a = (10, 10, 12, 20, 20, 30) rad/s².

* TOPP-RA's typical use, as its documentation shows: ``toppra.SplineInterpolator`` through the
  waypoints at a uniform parameter, ``JointVelocityConstraint`` + ``JointAccelerationConstraint``,
  ``TOPPRA(..., parametrizer="ParametrizeConstAccel")`` on its own proposed grid;
* rmtkit: ``time_parameterize(W, v, a, shape="spline")`` (the spline through every waypoint, its
  default grid, limits enforced on the whole continuous trajectory), and the default
  ``shape="blend"`` for reference.

Figures: compute time (median of repeats, whole call, single thread), duration, and the largest limit
overshoot of each trajectory on :data:`DENSE` uniform samples; TOPP-RA's duration is also given
slowed down (uniform time scaling by max(speed ratio, √acceleration ratio)) until it holds its limits
on those samples.  Targets (issue 22): duration no more than TOPP-RA's on the bench path, compute
time no more than TOPP-RA's.
"""
from __future__ import annotations

import logging
import os
import platform
import sys

import numpy as np

from planning.timing import time_parameterize
from studies.benchmarks.bench_timing import _median_time, fanuc_path, overshoot
from studies.benchmarks.driver import repeats_main

V = np.array([2.5, 2.5, 3.0, 5.0, 5.0, 7.0])
A = np.array([10.0, 10.0, 12.0, 20.0, 20.0, 30.0])
PATHS = {"bench (0.3–1.5 cycles)": (0.3, 1.5), "rougher (1–3 cycles)": (1.0, 3.0),
         "roughest (2–5 cycles)": (2.0, 5.0)}
DENSE = 20000
REPEATS = 9
QUICK_REPEATS = 3


def toppra_typical(W: np.ndarray):
    """TOPP-RA as its documentation shows it (module docstring)."""
    import toppra
    import toppra.algorithm
    import toppra.constraint
    path = toppra.SplineInterpolator(np.linspace(0.0, 1.0, len(W)), W)
    inst = toppra.algorithm.TOPPRA([toppra.constraint.JointVelocityConstraint(np.c_[-V, V]),
                                    toppra.constraint.JointAccelerationConstraint(np.c_[-A, A])],
                                   path, parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory()
    if traj is None:
        raise RuntimeError("TOPP-RA failed")
    return traj, len(inst.problem_data.gridpoints)


def run(quick: bool = False) -> dict:
    repeats = QUICK_REPEATS if quick else REPEATS
    logging.getLogger("toppra").setLevel(logging.ERROR)
    try:
        import toppra  # noqa: F401 - probes the peer
        have = True
    except ImportError:
        have = False
    load0 = os.getloadavg()[0]
    recs = {}
    for name, freq in PATHS.items():
        W = fanuc_path(freq=freq)
        rec = {}
        for shape in ("spline", "blend"):
            t, tr = _median_time(lambda: time_parameterize(W, V, A, shape=shape), repeats)
            ov = overshoot(*tr.sample(np.linspace(0, tr.duration, DENSE))[1:], V, A)
            rec[shape] = {"time_ms": 1e3 * t, "duration_s": tr.duration, "grid": len(tr.grid),
                          "velocity_ratio": ov["velocity_ratio"], "acceleration_ratio": ov["acceleration_ratio"]}
        if have:
            t, (jt, grid) = _median_time(lambda: toppra_typical(W), repeats)
            ts = np.linspace(0, jt.duration, DENSE)
            ov = overshoot(jt(ts, 1), jt(ts, 2), V, A)
            vr, ar = ov["velocity_ratio"], ov["acceleration_ratio"]
            d = float(jt.duration)
            rec["toppra"] = {"time_ms": 1e3 * t, "duration_s": d, "grid": grid, "velocity_ratio": vr,
                             "acceleration_ratio": ar, "duration_holding_limits_s": d * max(1.0, vr, ar ** 0.5)}
            rec["duration_ratio"] = rec["spline"]["duration_s"] / d
            rec["time_ratio"] = rec["spline"]["time_ms"] / rec["toppra"]["time_ms"]
        recs[name] = rec
    return {"benchmark": "waypoints", "robot": "fanuc_m16ib20", "waypoints": 100, "v_max": V.tolist(),
            "a_max": A.tolist(), "quick": quick, "paths": recs,
            "environment": {"python": platform.python_version(), "cpu_count": os.cpu_count(), "toppra": have,
                            "loadavg_1min_before": load0, "loadavg_1min_after": os.getloadavg()[0]}}


def format_report(R: dict) -> str:
    env = R["environment"]
    L = [f"bench_waypoints — {R['robot']}, {R['waypoints']} waypoints, v = {R['v_max']} rad/s, "
         f"a = {R['a_max']} rad/s²{' [quick]' if R['quick'] else ''}",
         f"load average (1 min) before / after: {env['loadavg_1min_before']:.2f} / {env['loadavg_1min_after']:.2f}"]
    if env["loadavg_1min_before"] > 0.5 * (env["cpu_count"] or 1):
        L.append("WARNING: the machine is loaded; treat the times as provisional")
    if not env["toppra"]:
        L.append("toppra is not installed (pip install -e '.[bench]'): no peer figures")
    for k, (name, rec) in enumerate(R["paths"].items()):
        L.append(f"{name}:")
        for shape in ("spline", "blend"):
            r = rec[shape]
            L.append(f"   rmtkit shape={shape:6s} {r['time_ms']:7.2f} ms  duration {r['duration_s']:.4f} s  "
                     f"(grid {r['grid']}; speed ×{r['velocity_ratio']:.4f}, "
                     f"acceleration ×{r['acceleration_ratio']:.4f})")
        if "toppra" in rec:
            t = rec["toppra"]
            L.append(f"   TOPP-RA typical     {t['time_ms']:7.2f} ms  duration {t['duration_s']:.4f} s  "
                     f"(grid {t['grid']}; speed ×{t['velocity_ratio']:.4f}, "
                     f"acceleration ×{t['acceleration_ratio']:.4f} between its grid points; "
                     f"{t['duration_holding_limits_s']:.4f} s slowed to hold them)")
            tag = (lambda ok: "PASS" if ok else "MISS") if k == 0 else (lambda ok: "ok" if ok else "over")
            L.append(f"   ratios spline/TOPP-RA: duration {rec['duration_ratio']:.4f} "
                     f"[{tag(rec['duration_ratio'] <= 1)}]"
                     f", compute time {rec['time_ratio']:.3f} [{tag(rec['time_ratio'] <= 1)}]"
                     + ("" if k == 0 else "  (no target: shown for transparency)"))
    return "\n".join(L)


def main(argv: list[str] | None = None) -> int:
    return repeats_main("bench_waypoints", __doc__, run, format_report, QUICK_REPEATS, REPEATS, argv)


if __name__ == "__main__":
    sys.exit(main())
