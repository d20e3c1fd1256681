"""Inverse-dynamics benchmark: rmtkit's recursive Newton–Euler (the compiled kernel of
``kin.dynamics.evaluator``) against pinocchio's ``rnea`` and ``crba``, on the same robot.

Run as ``python -m studies.benchmarks.bench_dynamics [--json] [--quick]`` (part of ``make bench``).
The robot is example-robot-data's UR5 URDF: pinocchio reads the file (``buildModelFromUrdf``),
rmtkit imports it (``kin.urdf.import_urdf``, the inertias in its DH frames), so both compute the same
model.  Everything on one thread (``RMTKIT_THREADS=1``; pinocchio's serial functions, its batch
``rneaInParallel`` with one thread).

1. agreement: max relative difference of τ (``rnea``) and M (``crba``, symmetrised) over random
   states, and of the compiled evaluator against CasADi's VM (``backend="vm"``);
2. one call (µs, median of repeats): rmtkit ``Robot.inverse_dynamics(q, qd, qdd)`` and
   ``Robot.mass_matrix(q)`` through the Python API (validation included), through the
   lowest-overhead documented entry (``Robot.dynamics_evaluator.single.tau(q, qd, qdd, p)``, the
   extension module: exact float64 (n,) arrays, None for anything else), and through the VM (the
   old baseline), against ``pin.rnea`` / ``pin.crba`` called from Python — the peer the way its docs
   show;
3. a batch of N states (µs per state): rmtkit's batch calls (τ and M) against a Python loop of
   ``pin.rnea`` / ``pin.crba`` and against pinocchio's own batch ``pin.rneaInParallel`` on one thread.

Targets (PASS/MISS, from the issue): one rmtkit RNEA call through the public API no slower than
pinocchio's (~1 µs per call for a 6R); the mass matrix no slower than ``crba``; the batch no slower
per state than pinocchio's batch.  A MISS does not change the exit status (0); an error does.
Figures taken under foreign load are flagged unreliable.
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


def _per_state_us(fn, N: int) -> float:
    return 1e6 * min(timeit.repeat(fn, repeat=3, number=1)) / N


def run(log, quick: bool = False) -> dict:
    os.environ["RMTKIT_THREADS"] = "1"
    import pinocchio as pin

    import kin
    from kin.urdf import import_urdf
    say = log or (lambda s: None)
    path = _urdf_path()
    chain = import_urdf(path, tip="tool0", collision=False)
    robot, vm = kin.Robot(chain), kin.Robot(chain, backend="vm")
    ev = robot.dynamics_evaluator
    ev.threads = 1
    model = pin.buildModelFromUrdf(path)
    data = model.createData()
    n = robot.n
    rng = np.random.default_rng(0)
    N = 2_000 if quick else 20_000
    Q = rng.uniform(robot.chain.lower, robot.chain.upper, size=(N, n))
    QD, QDD = rng.normal(size=(N, n)), rng.normal(size=(N, n))
    say(f"bench_dynamics: UR5 ({n} joints), {N} random states, rmtkit backend {ev.backend}")
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
    rel = lambda a, b: float(np.abs(a - b).max() / np.abs(b).max())  # noqa: E731
    err_vm = max(rel(tau, vm.inverse_dynamics(Q[:K], QD[:K], QDD[:K])), rel(M, vm.mass_matrix(Q[:K])))
    repeat, number = (5, 200) if quick else (7, 2000)
    q, qd, qdd = Q[0], QD[0], QDD[0]
    ext, p = ev.single, ev.p_nominal
    with ForeignLoad() as load1:
        ours_rnea = _per_call_us(lambda: robot.inverse_dynamics(q, qd, qdd), repeat, number * 10)
        ours_crba = _per_call_us(lambda: robot.mass_matrix(q), repeat, number * 10)
        ext_rnea = _per_call_us(lambda: ext.tau(q, qd, qdd, p), repeat, number * 10) if ext else None
        ext_crba = _per_call_us(lambda: ext.mass_matrix(q, p), repeat, number * 10) if ext else None
        vm_rnea = _per_call_us(lambda: vm.inverse_dynamics(q, qd, qdd), repeat, max(number // 10, 20))
        pin_rnea = _per_call_us(lambda: pin.rnea(model, data, q, qd, qdd), repeat, number * 10)
        pin_crba = _per_call_us(lambda: pin.crba(model, data, q), repeat, number * 10)
    say(f"one call: rmtkit rnea {ours_rnea:.2f} µs, pinocchio {pin_rnea:.2f} µs")

    def pin_loop():
        for k in range(N):
            pin.rnea(model, data, Q[k], QD[k], QDD[k])

    def pin_crba_loop():
        for k in range(N):
            pin.crba(model, data, Q[k])

    Qt, QDt, QDDt = (np.asfortranarray(x.T) for x in (Q, QD, QDD))
    pool = pin.ModelPool(model, 1) if hasattr(pin, "rneaInParallel") else None
    with ForeignLoad() as load2:
        ours_batch = _per_state_us(lambda: robot.inverse_dynamics(Q, QD, QDD), N)
        ours_batch_m = _per_state_us(lambda: robot.mass_matrix(Q), N)
        pin_batch = _per_state_us(pin_loop, N)
        pin_batch_m = _per_state_us(pin_crba_loop, N)
        pin_par = _per_state_us(lambda: pin.rneaInParallel(1, pool, Qt, QDt, QDDt), N) if pool else None
    say(f"batch: rmtkit {ours_batch:.3f} µs/state, pinocchio loop {pin_batch:.2f} µs/state")
    pin_best = min(x for x in (pin_batch, pin_par) if x is not None)
    return {"robot": "UR5 (example-robot-data URDF)", "joints": n, "states": N, "quick": quick,
            "backend": ev.backend,
            "versions": {"pinocchio": pin.__version__, "python": platform.python_version()},
            "agreement": {"tau_max_rel": err_t, "mass_matrix_max_rel": err_m, "compiled_vs_vm_max_rel": err_vm,
                          "states": K},
            "single_us": {"rmtkit_rnea": ours_rnea, "rmtkit_rnea_extension": ext_rnea, "rmtkit_rnea_vm": vm_rnea,
                          "pinocchio_rnea": pin_rnea, "rmtkit_mass_matrix": ours_crba,
                          "rmtkit_mass_matrix_extension": ext_crba, "pinocchio_crba": pin_crba},
            "batch_us_per_state": {"rmtkit_rnea": ours_batch, "rmtkit_mass_matrix": ours_batch_m,
                                   "pinocchio_rnea_loop": pin_batch, "pinocchio_crba_loop": pin_batch_m,
                                   "pinocchio_rnea_in_parallel_1_thread": pin_par},
            "load": {"single": load1.as_dict(), "batch": load2.as_dict()},
            "targets": [{"name": "single RNEA call: rmtkit API / pin.rnea", "value": ours_rnea / pin_rnea,
                         "target": "<= 1", "pass": ours_rnea <= pin_rnea},
                        {"name": "single RNEA call: rmtkit API (µs)", "value": ours_rnea,
                         "target": "<= 1", "pass": ours_rnea <= 1.0},
                        {"name": "single mass matrix: rmtkit API / pin.crba", "value": ours_crba / pin_crba,
                         "target": "<= 1", "pass": ours_crba <= pin_crba},
                        {"name": "batch RNEA per state: rmtkit / best pinocchio", "value": ours_batch / pin_best,
                         "target": "<= 1", "pass": ours_batch <= pin_best},
                        {"name": "agreement with pinocchio (relative)", "value": max(err_t, err_m),
                         "target": "<= 1e-10", "pass": max(err_t, err_m) <= 1e-10},
                        {"name": "compiled vs CasADi VM (relative)", "value": err_vm,
                         "target": "<= 1e-12", "pass": err_vm <= 1e-12}]}


def format_report(R: dict) -> str:
    s, b, a = R["single_us"], R["batch_us_per_state"], R["agreement"]
    flag = lambda d: "" if d["reliable"] else "  UNRELIABLE (foreign load)"  # noqa: E731
    us = lambda x: "n/a" if x is None else f"{x:.2f} µs"  # noqa: E731
    ratio = lambda x, y: "" if x is None else f" (×{x / y:.2f})"  # noqa: E731
    par = b["pinocchio_rnea_in_parallel_1_thread"]
    lines = [f"bench_dynamics — {R['robot']}, {R['joints']} joints, 1 thread, rmtkit {R['backend']}; "
             f"pinocchio {R['versions']['pinocchio']}" + (" (quick)" if R["quick"] else ""),
             f"agreement over {a['states']} random states: τ {a['tau_max_rel']:.2e}, M {a['mass_matrix_max_rel']:.2e} "
             f"(max relative); compiled vs VM {a['compiled_vs_vm_max_rel']:.2e}",
             f"one call, τ: Robot.inverse_dynamics {us(s['rmtkit_rnea'])}{ratio(s['rmtkit_rnea'], s['pinocchio_rnea'])}"
             f", extension .tau {us(s['rmtkit_rnea_extension'])}"
             f"{ratio(s['rmtkit_rnea_extension'], s['pinocchio_rnea'])}"
             f", VM {us(s['rmtkit_rnea_vm'])}; pin.rnea {us(s['pinocchio_rnea'])}{flag(R['load']['single'])}",
             f"one call, M: Robot.mass_matrix {us(s['rmtkit_mass_matrix'])}"
             f"{ratio(s['rmtkit_mass_matrix'], s['pinocchio_crba'])}, extension .mass_matrix "
             f"{us(s['rmtkit_mass_matrix_extension'])}; pin.crba {us(s['pinocchio_crba'])}",
             f"batch of {R['states']} (µs/state): rmtkit τ {b['rmtkit_rnea']:.3f}, M {b['rmtkit_mass_matrix']:.3f}; "
             f"Python loop of pin.rnea {b['pinocchio_rnea_loop']:.2f}, of pin.crba {b['pinocchio_crba_loop']:.2f}; "
             f"pin.rneaInParallel(1 thread) {'n/a' if par is None else f'{par:.2f}'}{flag(R['load']['batch'])}",
             "targets"]
    for t in R["targets"]:
        lines.append(f"   {'PASS' if t['pass'] else 'MISS'}  {t['name']:46s} {t['value']:.3g}   target {t['target']}")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="bench_dynamics", description=__doc__.splitlines()[0])
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--quick", action="store_true", help="fewer states and repeats")
    args = p.parse_args(argv)
    return measure_and_print("bench_dynamics", args.json, lambda log: run(log, args.quick), format_report)


if __name__ == "__main__":
    sys.exit(main())
