"""Inverse-dynamics benchmark: rmtkit's CasADi recursive Newton–Euler against pinocchio's ``rnea`` and
``crba``, on the same robot.

Run as ``python -m studies.benchmarks.bench_dynamics [--json] [--quick]`` (part of ``make bench``).
The robot is example-robot-data's UR5 URDF: pinocchio reads the file (``buildModelFromUrdf``),
rmtkit imports it (``kin.urdf.import_urdf``, the inertias in its DH frames), so both compute the same
model.  Everything on one thread (``RMTKIT_THREADS=1``; pinocchio's serial functions).

1. agreement: max relative difference of τ (``rnea``) and M (``crba``, symmetrised) over random
   states;
2. one call (µs, median of repeats): rmtkit ``Robot.inverse_dynamics(q, qd, qdd)`` and
   ``Robot.mass_matrix(q)`` through the Python API (validation included) against ``pin.rnea`` /
   ``pin.crba`` called from Python — the peer the way its docs show;
3. a batch of N states (µs per state): rmtkit's batch call against a Python loop of ``pin.rnea``
   (pinocchio's Python API has no batch call on one thread).

Target (PASS/MISS, from the issue): one rmtkit RNEA call no slower than pinocchio's (~1 µs per call
for a 6R).  Today the dynamics run in CasADi's virtual machine, not yet through the compiled-evaluator
path of the kinematics, so expect a MISS; the figures are the baseline.  A MISS does not change the
exit status (0); an error does.  Figures taken under foreign load are flagged unreliable.
"""
from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import timeit

import numpy as np

from studies.benchmarks.driver import measure_and_print
from studies.benchmarks.load import ForeignLoad

URDF = "ur_description/urdf/ur5_robot.urdf"


def _urdf_path() -> str:
    from studies.benchmarks.collision_peers import erd_share
    share = erd_share()
    if share is None:
        raise RuntimeError("example-robot-data is not installed (the `bench` extra)")
    return str(share / "example-robot-data" / "robots" / URDF)


def _per_call_us(fn, repeat: int, number: int) -> float:
    return 1e6 * statistics.median(timeit.repeat(fn, repeat=repeat, number=number)) / number


def run(log, quick: bool = False) -> dict:
    os.environ["RMTKIT_THREADS"] = "1"
    import pinocchio as pin

    import kin
    from kin.urdf import import_urdf
    say = log or (lambda s: None)
    path = _urdf_path()
    robot = kin.Robot(import_urdf(path, tip="tool0", collision=False))
    model = pin.buildModelFromUrdf(path)
    data = model.createData()
    n = robot.n
    rng = np.random.default_rng(0)
    N = 2_000 if quick else 20_000
    Q = rng.uniform(robot.chain.lower, robot.chain.upper, size=(N, n))
    QD, QDD = rng.normal(size=(N, n)), rng.normal(size=(N, n))
    say(f"bench_dynamics: UR5 ({n} joints), {N} random states")
    # 1. agreement
    K = 200
    tau = robot.inverse_dynamics(Q[:K], QD[:K], QDD[:K])
    M = robot.mass_matrix(Q[:K])
    err_t = err_m = 0.0
    for k in range(K):
        t_ref = pin.rnea(model, data, Q[k], QD[k], QDD[k])
        m_ref = pin.crba(model, data, Q[k])
        m_ref = np.triu(m_ref) + np.triu(m_ref, 1).T
        err_t = max(err_t, float(np.abs(tau[k] - t_ref).max() / max(np.abs(t_ref).max(), 1e-300)))
        err_m = max(err_m, float(np.abs(M[k] - m_ref).max() / max(np.abs(m_ref).max(), 1e-300)))
    repeat, number = (5, 200) if quick else (7, 2000)
    q, qd, qdd = Q[0], QD[0], QDD[0]
    with ForeignLoad() as load1:
        ours_rnea = _per_call_us(lambda: robot.inverse_dynamics(q, qd, qdd), repeat, number)
        ours_crba = _per_call_us(lambda: robot.mass_matrix(q), repeat, number)
        pin_rnea = _per_call_us(lambda: pin.rnea(model, data, q, qd, qdd), repeat, number * 10)
        pin_crba = _per_call_us(lambda: pin.crba(model, data, q), repeat, number * 10)
    say(f"one call: rmtkit rnea {ours_rnea:.1f} µs, pinocchio {pin_rnea:.2f} µs")

    def pin_loop():
        for k in range(N):
            pin.rnea(model, data, Q[k], QD[k], QDD[k])

    with ForeignLoad() as load2:
        ours_batch = 1e6 * min(timeit.repeat(lambda: robot.inverse_dynamics(Q, QD, QDD), repeat=3, number=1)) / N
        pin_batch = 1e6 * min(timeit.repeat(pin_loop, repeat=3, number=1)) / N
    say(f"batch: rmtkit {ours_batch:.2f} µs/state, pinocchio loop {pin_batch:.2f} µs/state")
    return {"robot": "UR5 (example-robot-data URDF)", "joints": n, "states": N, "quick": quick,
            "versions": {"pinocchio": pin.__version__, "python": platform.python_version()},
            "agreement": {"tau_max_rel": err_t, "mass_matrix_max_rel": err_m, "states": K},
            "single_us": {"rmtkit_rnea": ours_rnea, "pinocchio_rnea": pin_rnea, "rmtkit_mass_matrix": ours_crba,
                          "pinocchio_crba": pin_crba},
            "batch_us_per_state": {"rmtkit_rnea": ours_batch, "pinocchio_rnea_loop": pin_batch},
            "load": {"single": load1.as_dict(), "batch": load2.as_dict()},
            "targets": [{"name": "single RNEA call: rmtkit / pinocchio", "value": ours_rnea / pin_rnea,
                         "target": "<= 1", "pass": ours_rnea <= pin_rnea},
                        {"name": "agreement with pinocchio (relative)", "value": max(err_t, err_m),
                         "target": "<= 1e-10", "pass": max(err_t, err_m) <= 1e-10}]}


def format_report(R: dict) -> str:
    s, b, a = R["single_us"], R["batch_us_per_state"], R["agreement"]
    flag = lambda d: "" if d["reliable"] else "  UNRELIABLE (foreign load)"  # noqa: E731
    lines = [f"bench_dynamics — {R['robot']}, {R['joints']} joints, 1 thread; pinocchio {R['versions']['pinocchio']}"
             + (" (quick)" if R["quick"] else ""),
             f"agreement over {a['states']} random states: τ {a['tau_max_rel']:.2e}, M {a['mass_matrix_max_rel']:.2e} "
             "(max relative)",
             f"one call: rmtkit inverse_dynamics {s['rmtkit_rnea']:.1f} µs, pin.rnea {s['pinocchio_rnea']:.2f} µs "
             f"(×{s['rmtkit_rnea'] / s['pinocchio_rnea']:.0f}); rmtkit mass_matrix {s['rmtkit_mass_matrix']:.1f} µs, "
             f"pin.crba {s['pinocchio_crba']:.2f} µs{flag(R['load']['single'])}",
             f"batch of {R['states']}: rmtkit {b['rmtkit_rnea']:.2f} µs/state, Python loop of pin.rnea "
             f"{b['pinocchio_rnea_loop']:.2f} µs/state{flag(R['load']['batch'])}", "targets"]
    for t in R["targets"]:
        lines.append(f"   {'PASS' if t['pass'] else 'MISS'}  {t['name']:42s} {t['value']:.3g}   target {t['target']}")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="bench_dynamics", description=__doc__.splitlines()[0])
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--quick", action="store_true", help="fewer states and repeats")
    args = p.parse_args(argv)
    return measure_and_print("bench_dynamics", args.json, lambda log: run(log, args.quick), format_report)


if __name__ == "__main__":
    sys.exit(main())
