"""Timing benchmark: rmtkit's time parameterisation against TOPP-RA on the same path and grid.

Run as ``python -m studies.benchmarks.bench_timing [--json] [--quick]`` (part of ``make bench``).

The path: :data:`WAYPOINTS` joint waypoints of the FANUC M-16iB/20 (``fanuc_path``: a sum of three
random sinusoids per joint, fixed seed, inside the joint limits), blended by
:func:`planning.timing.blend_path` (quadratic Bézier corners of ``blend`` = 0.05 rad).  TOPP-RA gets
that very geometric path — the C¹ piecewise-quadratic spline q(s), through :class:`ToppraPath`, an
``AbstractGeometricPath`` over :meth:`BlendedPath.evaluate` — and the same grid (:data:`GRIDS`
points, uniform in s), with ``JointVelocityConstraint``, ``JointAccelerationConstraint`` and
``TOPPRA(..., parametrizer="ParametrizeConstAccel")``, as toppra's documentation shows.

Limits: the robot file has no maker's joint speeds, so :data:`V_MAX` are FANUC's published
M-16iB/20 figures (165, 165, 175, 350, 340, 520 °/s) and :data:`A_MAX` twice those per second (an
assumption: full speed in 0.5 s).

Figures per grid: compute time (median of repeats, whole call: rmtkit's ``time_parameterize``
including blending and its own dense re-check; TOPP-RA's constraints, instance and
``compute_trajectory``), duration, their ratios, and the largest limit overshoot between
grid points for both — |q̇_j|/v_j and |q̈_j|/A_j on :data:`DENSE` uniform times per grid interval of
each trajectory, over 1 (0: none).  Targets (issue 9): duration within 0.5 % of TOPP-RA's and compute
time no more than TOPP-RA's (≤ 20 ms at 1001 points).

Jerk (issue 22): the same call with ``j_max`` = :data:`J_MAX` (an assumption: full acceleration in
0.2 s) on each grid — compute time (target ≤ :data:`JERK_TARGET_MS` ms at 301 points) and duration; and
:data:`PTP_MOVES` random rest-to-rest 6-joint moves inside the joint limits (fixed seed), rmtkit's
``ptp_move`` (time synchronisation) against Ruckig (``Ruckig(dof)``, an ``InputParameter``, one
``calculate`` per move into a ``Trajectory``, as its documentation shows; single thread): the ratio of
the durations (max and median of rmtkit/Ruckig) and the compute time per move.  The report states the
machine's load: figures taken while other processes run are not reliable.
"""
from __future__ import annotations

import os
import platform
import statistics
import sys
import time

import numpy as np

import kin
from planning.timing import BlendedPath, blend_path, ptp_move, time_parameterize
from studies.benchmarks.driver import repeats_main

WAYPOINTS = 100
GRIDS = (301, 1001)
SEED = 7
V_MAX = np.radians([165.0, 165.0, 175.0, 350.0, 340.0, 520.0])
A_MAX = 2.0 * V_MAX
BLEND = 0.05
DENSE = 20
REPEATS = 15
QUICK_REPEATS = 3
DURATION_TOL = 0.005        # relative duration target against TOPP-RA
J_MAX = 5.0 * A_MAX
JERK_TARGET_MS = 20.0
PTP_MOVES = 1000
QUICK_PTP_MOVES = 100


def fanuc_path(seed: int = SEED, m: int = WAYPOINTS, freq: tuple[float, float] = (0.3, 1.5)) -> np.ndarray:
    """(m, 6) waypoints of a smooth random FANUC M-16iB/20 joint path inside its joint limits (three
    sinusoids per joint, frequencies uniform in ``freq`` cycles over the path)."""
    lim = kin.load_robot("fanuc_m16ib20").chain.limits
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 1.0, m)[:, None]
    f = rng.uniform(*freq, (3, 6))
    ph = rng.uniform(0, 2 * np.pi, (3, 6))
    x = sum(np.sin(2 * np.pi * f[k] * u + ph[k]) for k in range(3)) / 3.0       # in [−1, 1]
    mid, half = lim.mean(axis=1), 0.4 * (lim[:, 1] - lim[:, 0]) / 2
    return mid + half * x


class ToppraPath:
    """toppra's ``AbstractGeometricPath`` interface over a :class:`BlendedPath` (built lazily so that
    this module imports without toppra)."""

    def __new__(cls, bp: BlendedPath):
        from toppra.interpolator import AbstractGeometricPath

        class _Path(AbstractGeometricPath):
            def __call__(self, path_positions, order: int = 0):
                s = np.asarray(path_positions, dtype=float)
                out = bp.evaluate(np.atleast_1d(s))[order]
                return out[0] if s.ndim == 0 else out

            @property
            def dof(self) -> int:
                return bp.n

            @property
            def path_interval(self):
                return np.array([0.0, bp.length])

        return _Path()


def toppra_solve(bp: BlendedPath, grid: np.ndarray, v_max: np.ndarray, a_max: np.ndarray):
    """TOPP-RA on path ``bp`` and grid ``grid`` (the documented recipe); its joint trajectory."""
    import toppra
    import toppra.algorithm
    import toppra.constraint

    pc_vel = toppra.constraint.JointVelocityConstraint(np.c_[-v_max, v_max])
    pc_acc = toppra.constraint.JointAccelerationConstraint(np.c_[-a_max, a_max])
    instance = toppra.algorithm.TOPPRA([pc_vel, pc_acc], ToppraPath(bp), gridpoints=grid,
                                       parametrizer="ParametrizeConstAccel")
    traj = instance.compute_trajectory()
    if traj is None:
        raise RuntimeError(f"TOPP-RA failed: {instance.problem_data.return_code}")
    return traj


def overshoot(qd: np.ndarray, qdd: np.ndarray, v_max: np.ndarray, a_max: np.ndarray) -> dict:
    """Largest speed and acceleration ratios to the limits and the overshoot max(ratio − 1, 0)."""
    vr = float(np.max(np.abs(qd) / v_max))
    ar = float(np.max(np.abs(qdd) / a_max))
    return {"velocity_ratio": vr, "acceleration_ratio": ar, "overshoot": max(vr - 1.0, ar - 1.0, 0.0)}


def _median_time(f, repeats: int) -> tuple[float, object]:
    out = f()                                   # warm-up (compiles or loads the C passes once)
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), out


def run(quick: bool = False) -> dict:
    repeats = QUICK_REPEATS if quick else REPEATS
    W = fanuc_path()
    bp = blend_path(W, BLEND)
    load0 = os.getloadavg()[0]
    try:
        import toppra  # noqa: F401 - only probes that TOPP-RA is installed
        have_toppra = True
    except ImportError:
        have_toppra = False
    grids = {}
    for npts in GRIDS:
        K = npts - 1
        ds = bp.length / K * (1 + 1e-12)
        t_r, tr = _median_time(lambda: time_parameterize(W, V_MAX, A_MAX, ds=ds, blend=BLEND), repeats)
        assert len(tr.grid) == npts
        times = np.linspace(0.0, tr.duration, DENSE * K + 1)
        _, qd, qdd = tr.sample(times)
        rec = {"rmtkit": {"time_ms": 1e3 * t_r, "duration_s": tr.duration, "solver": tr.qp_status,
                          **overshoot(qd, qdd, V_MAX, A_MAX), "own_recheck_overshoot": tr.overshoot}}
        if K <= 300:
            t_q, trq = _median_time(lambda: time_parameterize(W, V_MAX, A_MAX, ds=ds, blend=BLEND, method="qp"),
                                    1 if quick else 3)
            rec["rmtkit_qp"] = {"time_ms": 1e3 * t_q, "duration_s": trq.duration}
        if have_toppra:
            t_t, jt = _median_time(lambda: toppra_solve(bp, tr.grid, V_MAX, A_MAX), repeats)
            times = np.linspace(0.0, jt.duration, DENSE * K + 1)
            rec["toppra"] = {"time_ms": 1e3 * t_t, "duration_s": float(jt.duration),
                             **overshoot(jt(times, 1), jt(times, 2), V_MAX, A_MAX)}
            rec["time_ratio"] = t_r / t_t
            rec["duration_ratio"] = tr.duration / float(jt.duration)
            rec["targets"] = {"duration_within_0.5%": abs(rec["duration_ratio"] - 1) <= DURATION_TOL,
                              "time_no_more_than_toppra": t_r <= t_t}
        t_j, trj = _median_time(lambda: time_parameterize(W, V_MAX, A_MAX, ds=ds, blend=BLEND, j_max=J_MAX),
                                repeats)
        rec["jerk"] = {"time_ms": 1e3 * t_j, "duration_s": trj.duration, "max_jerk_ratio": trj.max_jerk_ratio,
                       "solver": trj.qp_status, "target_ms": JERK_TARGET_MS if npts == GRIDS[0] else None,
                       "pass": (1e3 * t_j <= JERK_TARGET_MS) if npts == GRIDS[0] else None}
        grids[str(npts)] = rec
    return {"benchmark": "timing", "robot": "fanuc_m16ib20", "waypoints": WAYPOINTS, "blend": BLEND,
            "path_length": bp.length, "v_max": V_MAX.tolist(), "a_max": A_MAX.tolist(), "j_max": J_MAX.tolist(),
            "quick": quick, "grids": grids, "ptp": ptp_compare(QUICK_PTP_MOVES if quick else PTP_MOVES),
            "environment": {"python": platform.python_version(), "numpy": np.__version__,
                            "cpu_count": os.cpu_count(), "toppra": have_toppra,
                            "loadavg_1min_before": load0, "loadavg_1min_after": os.getloadavg()[0]}}


def ptp_compare(moves: int, seed: int = SEED) -> dict:
    """rmtkit's ``ptp_move`` against Ruckig on ``moves`` random rest-to-rest moves (module docstring)."""
    lim = kin.load_robot("fanuc_m16ib20").chain.limits
    rng = np.random.default_rng(seed)
    Q0 = rng.uniform(lim[:, 0], lim[:, 1], (moves, 6))
    Q1 = rng.uniform(lim[:, 0], lim[:, 1], (moves, 6))
    ptp_move(Q0[0], Q1[0], V_MAX, A_MAX, J_MAX)            # warm-up
    t0 = time.perf_counter()
    ours = np.array([ptp_move(a, b, V_MAX, A_MAX, J_MAX).duration for a, b in zip(Q0, Q1)])
    rec = {"moves": moves, "rmtkit_us_per_move": 1e6 * (time.perf_counter() - t0) / moves}
    try:
        import ruckig
    except ImportError:
        return rec
    otg, inp, traj = ruckig.Ruckig(6), ruckig.InputParameter(6), ruckig.Trajectory(6)
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = V_MAX.tolist(), A_MAX.tolist(), J_MAX.tolist()
    theirs = np.empty(moves)
    t0 = time.perf_counter()
    for k in range(moves):
        inp.current_position, inp.target_position = Q0[k].tolist(), Q1[k].tolist()
        if otg.calculate(inp, traj) != ruckig.Result.Working:
            raise RuntimeError(f"Ruckig failed on move {k}")
        theirs[k] = traj.duration
    rec["ruckig_us_per_move"] = 1e6 * (time.perf_counter() - t0) / moves
    ratio = ours / theirs
    rec["duration_ratio_max"] = float(np.max(ratio))
    rec["duration_ratio_median"] = float(np.median(ratio))
    rec["duration_ratio_min"] = float(np.min(ratio))
    return rec


def format_report(R: dict) -> str:
    env = R["environment"]
    L = [f"bench_timing — {R['robot']}, {R['waypoints']} waypoints, blend {R['blend']} rad, path length "
         f"{R['path_length']:.3f} rad{' [quick]' if R['quick'] else ''}",
         f"load average (1 min) before / after: {env['loadavg_1min_before']:.2f} / {env['loadavg_1min_after']:.2f}"
         " — other processes on the machine distort every timing below"]
    if env["loadavg_1min_before"] > 0.5 * (env["cpu_count"] or 1):
        L.append("WARNING: the machine is loaded; treat the times as provisional")
    if not env["toppra"]:
        L.append("toppra is not installed (pip install -e '.[bench]'): no peer figures")
    for npts, rec in R["grids"].items():
        r = rec["rmtkit"]
        L.append(f"grid {npts} points:")
        L.append(f"   rmtkit  {r['time_ms']:8.2f} ms  duration {r['duration_s']:.5f} s  overshoot between grid points "
                 f"{r['overshoot']:.2e}  ({r['solver']})")
        if "rmtkit_qp" in rec:
            q = rec["rmtkit_qp"]
            L.append(f"   rmtkit method='qp' (OSQP) {q['time_ms']:8.1f} ms  duration {q['duration_s']:.5f} s")
        if "toppra" in rec:
            t = rec["toppra"]
            L.append(f"   TOPP-RA {t['time_ms']:8.2f} ms  duration {t['duration_s']:.5f} s  "
                     f"overshoot between grid points {t['overshoot']:.2e} "
                     f"(speed ×{t['velocity_ratio']:.4f}, acceleration ×{t['acceleration_ratio']:.4f})")
            ok = rec["targets"]
            L.append(f"   ratios rmtkit/TOPP-RA: time {rec['time_ratio']:.3f} "
                     f"[{'PASS' if ok['time_no_more_than_toppra'] else 'MISS'}], duration {rec['duration_ratio']:.5f} "
                     f"[{'PASS' if ok['duration_within_0.5%'] else 'MISS'} ±0.5 %]")
        j = rec["jerk"]
        tgt = "" if j["target_ms"] is None else f" [{'PASS' if j['pass'] else 'MISS'} ≤ {j['target_ms']:.0f} ms]"
        L.append(f"   rmtkit j_max = 5·a_max {j['time_ms']:8.2f} ms{tgt}  duration {j['duration_s']:.5f} s  "
                 f"jerk ratio {j['max_jerk_ratio']:.9f}  ({j['solver']})")
    p = R["ptp"]
    line = f"point-to-point, {p['moves']} random 6-joint moves: rmtkit ptp_move {p['rmtkit_us_per_move']:.1f} µs/move"
    if "ruckig_us_per_move" in p:
        line += (f", Ruckig {p['ruckig_us_per_move']:.1f} µs/move; duration rmtkit/Ruckig max "
                 f"{p['duration_ratio_max']:.12f}, median {p['duration_ratio_median']:.12f}, "
                 f"min {p['duration_ratio_min']:.12f}")
    else:
        line += " (ruckig not installed: pip install -e '.[bench]')"
    L.append(line)
    return "\n".join(L)


def main(argv: list[str] | None = None) -> int:
    return repeats_main("bench_timing", __doc__, run, format_report, QUICK_REPEATS, REPEATS, argv)


if __name__ == "__main__":
    sys.exit(main())
