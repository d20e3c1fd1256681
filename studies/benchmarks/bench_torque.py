"""Torque-limited timing benchmark: rmtkit's ``time_parameterize(..., robot=, tau_max=)`` against
TOPP-RA with ``JointTorqueConstraint`` on the same path and grid.

Run as ``python -m studies.benchmarks.bench_torque [--json] [--quick]`` (part of ``make bench``).

The robot: the bundled ``franka_panda`` (inertias of example-robot-data's Panda, links 1–7, no hand).
The path: :data:`WAYPOINTS` joint waypoints (a sum of three random sinusoids per joint, fixed seed,
inside 40 % of the joint ranges), blended by :func:`planning.timing.blend_path` (``blend`` = 0.05
rad).  TOPP-RA gets that very path (:class:`studies.benchmarks.bench_timing.ToppraPath`), the same
grid, ``JointVelocityConstraint``, ``JointAccelerationConstraint`` and ``JointTorqueConstraint``
whose ``inv_dyn`` is pinocchio's ``rnea`` on example-robot-data's ``panda.urdf`` with the hand links
removed (the same model: checked against ``Robot.inverse_dynamics`` to 1e-9 relative before timing)
— the fastest honest peer, used as toppra's documentation shows.  Single thread.

Limits: the file's joint speeds, 3 × Franka's published joint accelerations (:data:`A_MAX`) and
:data:`TAU_SCALE` × Franka's published torques (87, 87, 87, 87, 12, 12, 12 N·m), so that the torque
limits bind on this path (with the published values they do not: peak |τ|/τmax 0.51).

Figures per grid: compute time (median of repeats, the whole call), duration, their ratios, and the
largest torque ratio |τ_j|/τmax_j between grid points of both trajectories (inverse dynamics at
:data:`DENSE` uniform times per grid interval), with speed/acceleration overshoots.  Targets: duration
within 0.5 % of TOPP-RA's or shorter, compute time no more than TOPP-RA's.
"""
from __future__ import annotations

import os
import platform
import sys
import xml.etree.ElementTree as ET

import numpy as np

import kin
from planning.timing import blend_path, time_parameterize
from studies.benchmarks.bench_timing import ToppraPath, _median_time, overshoot
from studies.benchmarks.driver import repeats_main

os.environ.setdefault("RMTKIT_THREADS", "1")

WAYPOINTS = 30
GRIDS = (301, 1001)
SEED = 11
ROBOT = "franka_panda"
#: 3 × Franka's published joint accelerations: torque, not acceleration, is what binds
A_MAX = 3.0 * np.array([15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0])
TAU_SCALE = 0.5
TAU_MAX = TAU_SCALE * np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0])
BLEND = 0.05
DENSE = 20
REPEATS = 7
QUICK_REPEATS = 2
DURATION_TOL = 0.005


def panda_path(seed: int = SEED, m: int = WAYPOINTS) -> np.ndarray:
    lim = kin.load_chain(ROBOT).limits
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 1.0, m)[:, None]
    f = rng.uniform(0.3, 1.5, (3, 7))
    ph = rng.uniform(0, 2 * np.pi, (3, 7))
    x = sum(np.sin(2 * np.pi * f[k] * u + ph[k]) for k in range(3)) / 3.0
    return lim.mean(axis=1) + 0.4 * (lim[:, 1] - lim[:, 0]) / 2 * x


def pinocchio_panda():
    """pinocchio model and data of example-robot-data's panda.urdf without the hand (links 0–7)."""
    import pinocchio as pin

    from studies.benchmarks.collision_peers import erd_share
    share = erd_share()
    if share is None:
        raise RuntimeError("example-robot-data is not installed (the `bench` extra)")
    root = ET.parse(share / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf").getroot()
    keep = {f"panda_link{i}" for i in range(8)}
    for link in list(root.findall("link")):
        if link.get("name") not in keep:
            root.remove(link)
    for joint in list(root.findall("joint")):
        if joint.find("child").get("link") not in keep:
            root.remove(joint)
    model = pin.buildModelFromXML(ET.tostring(root, encoding="unicode"))
    return model, model.createData()


def toppra_solve(bp, grid, vmax, amax, tmax, inv_dyn):
    import toppra
    import toppra.algorithm
    import toppra.constraint

    cons = [toppra.constraint.JointVelocityConstraint(np.c_[-vmax, vmax]),
            toppra.constraint.JointAccelerationConstraint(np.c_[-amax, amax]),
            toppra.constraint.JointTorqueConstraint(inv_dyn, np.c_[-tmax, tmax], np.zeros(len(tmax)))]
    inst = toppra.algorithm.TOPPRA(cons, ToppraPath(bp), gridpoints=grid, parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory()
    if traj is None:
        raise RuntimeError(f"TOPP-RA failed: {inst.problem_data.return_code}")
    return traj


def _torque_ratio(robot, q, qd, qdd) -> float:
    return float(np.max(np.abs(robot.inverse_dynamics(q, qd, qdd)) / TAU_MAX))


def slowed_to_hold(robot, q, qd, qdd, vmax) -> float:
    """The smallest uniform time scale f ≥ 1 that makes a sampled trajectory hold every limit: speeds
    scale with 1/f, accelerations and the non-gravity torque τ − g(q) with 1/f² (no friction in this
    model); by bisection on the samples."""
    g = robot.gravity(q)
    dyn = robot.inverse_dynamics(q, qd, qdd) - g

    def holds(f: float) -> bool:
        return (np.max(np.abs(qd) / vmax) <= f and np.max(np.abs(qdd) / A_MAX) <= f * f
                and np.max(np.abs(g + dyn / (f * f)) / TAU_MAX) <= 1.0)
    lo, hi = 1.0, 1.0
    while not holds(hi):
        lo, hi = hi, 2 * hi
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if holds(mid) else (mid, hi)
    return 1.0 if holds(1.0) else hi


def run(quick: bool = False) -> dict:
    repeats = QUICK_REPEATS if quick else REPEATS
    robot = kin.load_robot(ROBOT)
    vmax = np.array([j.max_velocity for j in robot.chain.joints])
    W = panda_path()
    bp = blend_path(W, BLEND)
    load0 = os.getloadavg()[0]
    try:
        import pinocchio as pin
        import toppra  # noqa: F401 - only probes that TOPP-RA is installed
        model, data = pinocchio_panda()
        Q = robot.random_configurations(20, seed=1)
        rng = np.random.default_rng(2)
        QD, QDD = rng.normal(size=Q.shape), rng.normal(size=Q.shape)
        ref = np.array([pin.rnea(model, data, Q[k], QD[k], QDD[k]) for k in range(len(Q))])
        err = float(np.max(np.abs(ref - robot.inverse_dynamics(Q, QD, QDD))) / np.max(np.abs(ref)))
        if err > 1e-9:
            raise RuntimeError(f"pinocchio's Panda disagrees with rmtkit's by {err:.1e}")

        def inv_dyn(q, v, a):
            return pin.rnea(model, data, q, v, a)
        have_peer = True
    except (ImportError, RuntimeError) as e:
        have_peer, err, peer_note = False, None, str(e)
    grids = {}
    for npts in GRIDS:
        K = npts - 1
        ds = bp.length / K * (1 + 1e-12)

        def ours():
            return time_parameterize(W, vmax, A_MAX, ds=ds, blend=BLEND, robot=robot, tau_max=TAU_MAX)
        t_r, tr = _median_time(ours, repeats)
        times = np.linspace(0.0, tr.duration, DENSE * K + 1)
        q, qd, qdd = tr.sample(times)
        rec = {"rmtkit": {"time_ms": 1e3 * t_r, "duration_s": tr.duration, "solver": tr.qp_status,
                          "torque_ratio": _torque_ratio(robot, q, qd, qdd), "own_recheck_torque_ratio":
                          tr.max_torque_ratio, "tightening_rounds": tr.torque_rounds,
                          **overshoot(qd, qdd, vmax, A_MAX)}}
        if have_peer:
            t_t, jt = _median_time(lambda: toppra_solve(bp, tr.grid, vmax, A_MAX, TAU_MAX, inv_dyn), repeats)
            times = np.linspace(0.0, jt.duration, DENSE * K + 1)
            q, qd, qdd = jt(times), jt(times, 1), jt(times, 2)
            rec["toppra"] = {"time_ms": 1e3 * t_t, "duration_s": float(jt.duration),
                             "torque_ratio": _torque_ratio(robot, q, qd, qdd), **overshoot(qd, qdd, vmax, A_MAX),
                             "duration_holding_limits_s": float(jt.duration) * slowed_to_hold(robot, q, qd, qdd,
                                                                                              vmax)}
            rec["time_ratio"] = t_r / t_t
            rec["duration_ratio"] = tr.duration / float(jt.duration)
            rec["targets"] = {"duration_within_0.5%_or_shorter": rec["duration_ratio"] <= 1 + DURATION_TOL,
                              "time_no_more_than_toppra": t_r <= t_t}
        grids[str(npts)] = rec
    return {"benchmark": "torque", "robot": ROBOT, "waypoints": WAYPOINTS, "blend": BLEND, "path_length": bp.length,
            "v_max": vmax.tolist(), "a_max": A_MAX.tolist(), "tau_max": TAU_MAX.tolist(), "quick": quick,
            "grids": grids, "peer_model_agreement": err,
            "environment": {"python": platform.python_version(), "numpy": np.__version__, "cpu_count": os.cpu_count(),
                            "peer": have_peer if have_peer else peer_note, "loadavg_1min_before": load0,
                            "loadavg_1min_after": os.getloadavg()[0]}}


def format_report(R: dict) -> str:
    env = R["environment"]
    L = [f"bench_torque — {R['robot']}, {R['waypoints']} waypoints, blend {R['blend']} rad, path length "
         f"{R['path_length']:.3f} rad, tau_max {TAU_SCALE:g} × Franka's{' [quick]' if R['quick'] else ''}",
         f"load average (1 min) before / after: {env['loadavg_1min_before']:.2f} / {env['loadavg_1min_after']:.2f}"
         " — other processes on the machine distort every timing below"]
    if env["peer"] is not True:
        L.append(f"no TOPP-RA peer figures: {env['peer']} (pip install -e '.[bench]')")
    for npts, rec in R["grids"].items():
        r = rec["rmtkit"]
        L.append(f"grid {npts} points:")
        L.append(f"   rmtkit  {r['time_ms']:8.2f} ms  duration {r['duration_s']:.5f} s  |τ|/τmax between grid points "
                 f"{r['torque_ratio']:.5f}, speed/acc overshoot {r['overshoot']:.1e}  "
                 f"({r['tightening_rounds']} tightening rounds)")
        if "toppra" in rec:
            t = rec["toppra"]
            ok = rec["targets"]
            L.append(f"   TOPP-RA {t['time_ms']:8.2f} ms  duration {t['duration_s']:.5f} s  |τ|/τmax between grid "
                     f"points {t['torque_ratio']:.5f}, speed/acc overshoot {t['overshoot']:.1e}; "
                     f"{t['duration_holding_limits_s']:.5f} s slowed to hold every limit")
            L.append(f"   ratios rmtkit/TOPP-RA: time {rec['time_ratio']:.3f} "
                     f"[{'PASS' if ok['time_no_more_than_toppra'] else 'MISS'}], duration {rec['duration_ratio']:.5f} "
                     f"[{'PASS' if ok['duration_within_0.5%_or_shorter'] else 'MISS'} ≤ +0.5 %]")
    return "\n".join(L)


def main(argv: list[str] | None = None) -> int:
    return repeats_main("bench_torque", __doc__, run, format_report, QUICK_REPEATS, REPEATS, argv)


if __name__ == "__main__":
    sys.exit(main())
