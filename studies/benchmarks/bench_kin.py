"""Kinematics benchmark: batch throughput (1 thread and all threads), the loaded case, single-call
latency, start-up, peers, agreement.

Run as ``python -m studies.benchmarks.bench_kin [--json] [--robot NAME] [--quick]`` (part of
``make bench``).  For one 6-joint arm (default ``fanuc_m16ib20``) it measures

1. batch FK + 6×6 Jacobian + manipulability (and σ_min alone) in configurations/s at N = 1e5 (and
   1e6), once on 1 thread and once on all the threads the process may use (``RMTKIT_THREADS`` or
   the CPU affinity), each through the public call that allocates its outputs and through the same
   call writing into ``out=`` buffers;
2. the loaded case: the same calls at N = 1e3 and 1e5 while a second process spins on a CPU
   (:func:`studies.benchmarks.load.busy_process`, bounded in time, stopped afterwards);
3. single-call latency of ``robot.fk_jacobian(q)`` and friends (µs, timeit);
4. cold start (compile into an empty cache) and warm start (load from that cache), each in a fresh
   subprocess with its own temporary ``RMTKIT_CACHE``, timed inside the subprocess after the imports;
5. peers, when the optional ``bench`` extra is installed, each the fast way its docs show (one
   thread, a Python loop around their compiled calls): pinocchio (``computeFrameJacobian``,
   LOCAL_WORLD_ALIGNED) and roboticstoolbox-python (C++ ``ETS.eval`` / ``ETS.jacob0``, and the
   batch ``ETS.eval(Q)``), built from the chain's DH table (:mod:`studies.benchmarks.peers`);
6. agreement of T and J between rmtkit, pinocchio, roboticstoolbox and central finite differences.

Ratios compare like with like: rmtkit on 1 thread against the peers' single-threaded loops, single
calls against single calls; the multi-threaded figures are compared with rmtkit's own 1-thread ones.
Every section records the CPU share other processes took meanwhile
(:class:`studies.benchmarks.load.ForeignLoad`); figures measured above 10 % are flagged unreliable.
Targets (PASS/MISS): batch FK+J+manip ≥ 25e6 configurations/s on all threads (2 cores) at
N = 1e5 (into out= buffers, median); single FK+J ≤ 1.0 µs (median); under load, all threads ≥ 0.5×
the 1-thread throughput (no spin-wait collapse); cold start ≤ 15 s; warm start ≤ 0.3 s; agreement
with pinocchio and roboticstoolbox ≤ 1e-9.  A MISS does not change the exit status (0); an error does.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
import timeit

import numpy as np

import kin
from kin.compiled import WANT_J, WANT_MANIP, WANT_T, default_threads
from studies.benchmarks.driver import measure_and_print
from studies.benchmarks.kin_report import format_report
from studies.benchmarks.load import ForeignLoad, busy_process
from studies.benchmarks.peers import fd_jacobian, pinocchio_batch, pinocchio_loops, rtb_batch, rtb_loops

DEFAULT_ROBOT = "fanuc_m16ib20"
SEED = 20240611
WANT = WANT_T | WANT_J | WANT_MANIP

TARGETS = {
    # key: (description, comparison, threshold, unit)
    "batch_all_threads": ("batch FK+J+manip, all threads, out=", ">=", 25e6, "cfg/s"),
    "single_fk_jacobian_us": ("single fk_jacobian(q)", "<=", 1.0, "us"),
    "loaded_all_vs_1_thread": ("under load: all threads / 1 thread", ">=", 0.5, "x"),
    "cold_start_s": ("cold start (compile)", "<=", 15.0, "s"),
    "warm_start_s": ("warm start (cache)", "<=", 0.3, "s"),
    "agreement_pinocchio": ("max rel diff vs pinocchio (T, J)", "<=", 1e-9, ""),
    "agreement_rtb": ("max rel diff vs roboticstoolbox (T, J)", "<=", 1e-9, ""),
}


# ---- helpers -----------------------------------------------------------------------------
def _try_import(name: str):
    try:
        return __import__(name), None
    except Exception as e:  # ImportError, or a broken binary install
        return None, f"{name} not importable ({type(e).__name__}: {e}); install the 'bench' extra"


def _stats(times: list[float], count: int) -> dict:
    """Throughput figures of repeated timings of ``count`` configurations each."""
    best, med = min(times), statistics.median(times)
    return {"best_s": best, "median_s": med, "best_cfg_per_s": count / best, "median_cfg_per_s": count / med,
            "repeats": len(times)}


def _time_repeat(fn, repeats: int) -> list[float]:
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def _rel(a, b) -> float:
    """max |a − b| / max(1, |b|), elementwise."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b) / np.maximum(1.0, np.abs(b)))) if a.size else 0.0


def _latency_us(fn, number: int, repeat: int) -> dict:
    fn()
    per = [t / number * 1e6 for t in timeit.Timer(fn).repeat(repeat=repeat, number=number)]
    return {"best_us": min(per), "median_us": statistics.median(per), "calls": number, "repeats": repeat}


# ---- 1. batch ----------------------------------------------------------------------------
def _batch_calls(robot, N: int, seed: int):
    """(Q, public call allocating its outputs, the same call into out= buffers, σ_min into out=)."""
    Q = robot.random_configurations(N, seed=seed)
    out = {"T": np.empty((N, 4, 4)), "J": np.empty((N, 6, robot.n)), "manipulability": np.empty(N)}
    s = np.empty(N)
    return (Q, lambda: robot.evaluate(Q, WANT), lambda: robot.evaluate(Q, WANT, out=out),
            lambda: robot.sigma_min(Q, out=s))


def bench_batch(robot, sizes, repeats: int, thread_counts) -> dict:
    ev = robot.evaluator
    out: dict = {"want": "T|J|MANIP", "threads": {}}
    for th in thread_counts:
        ev.threads = th
        rec: dict = {}
        with ForeignLoad() as load:
            for N in sizes:
                _, alloc, into, sigma = _batch_calls(robot, N, SEED)
                alloc(), into()  # warm-up, first touch of the out= pages
                r = {"alloc": _stats(_time_repeat(alloc, repeats), N), "out": _stats(_time_repeat(into, repeats), N),
                     "threads_ran": getattr(ev, "last_threads", 1)}
                if N == sizes[0]:
                    sigma()
                    r["sigma_min_out"] = _stats(_time_repeat(sigma, repeats), N)
                rec[str(N)] = r
        rec["load"] = load.as_dict()
        out["threads"][str(th)] = rec
    ev.threads = None
    return out


# ---- 2. the loaded case ------------------------------------------------------------------
def bench_loaded(robot, thread_counts, seconds: float) -> dict:
    """Throughput on 1 thread and on all threads while a second process spins (bounded, then stopped)."""
    ev = robot.evaluator
    out: dict = {"busy_process_bound_s": seconds, "sizes": {}}
    calls = {N: _batch_calls(robot, N, SEED + 7)[2] for N in (1_000, 100_000)}
    for f in calls.values():
        f()
    proc = busy_process(seconds)
    try:
        time.sleep(0.2)  # let it start spinning
        for N, into in calls.items():
            rec = {}
            for th in thread_counts:
                ev.threads = th
                reps = 200 if N <= 1_000 else 5
                rec[str(th)] = _stats(_time_repeat(into, reps), N)
            out["sizes"][str(N)] = rec
        out["busy_process_still_running"] = proc.poll() is None
    finally:
        ev.threads = None
        proc.terminate()
        proc.wait(timeout=10)
    return out


# ---- 3. single call ----------------------------------------------------------------------
def bench_single(robot, number: int, repeat: int) -> dict:
    q = robot.random_configurations(1, seed=SEED + 2)[0]
    out = {"fk_jacobian": _latency_us(lambda: robot.fk_jacobian(q), number, repeat),
           "fk": _latency_us(lambda: robot.fk(q), number, repeat),
           "jacobian": _latency_us(lambda: robot.jacobian(q), number, repeat),
           "measures": _latency_us(lambda: robot.measures(q), number, repeat)}
    ext = getattr(robot.evaluator, "single", None)
    if ext is not None:  # the C call alone, for the wrapper's share of the latency
        p = robot.evaluator.p_nominal
        out["extension_fk_jacobian"] = _latency_us(lambda: ext.fk_jacobian(q, p), number, repeat)
    return out


# ---- 4. start-up -------------------------------------------------------------------------
_STARTUP_SCRIPT = textwrap.dedent("""
    import json, sys, time
    import numpy as np
    import kin
    name = sys.argv[1]
    t0 = time.perf_counter()
    robot = kin.load_robot(name)
    t1 = time.perf_counter()
    robot.symbolic.fkj_cs_function
    t2 = time.perf_counter()
    ev = robot.evaluator
    t3 = time.perf_counter()
    robot.fk(np.zeros(robot.n))
    t4 = time.perf_counter()
    extra = {}
    if hasattr(ev, "header"):
        s0 = time.perf_counter(); ev.header(); extra["codegen_again_s"] = time.perf_counter() - s0
    print(json.dumps({"total_s": t4 - t0, "load_chain_s": t1 - t0, "symbolic_s": t2 - t1,
                      "evaluator_s": t3 - t2, "first_fk_s": t4 - t3, "backend": ev.backend,
                      "cached": bool(getattr(ev, "cached", False)), **extra}))
""")


def bench_startup(name: str) -> dict:
    out = {}
    with tempfile.TemporaryDirectory(prefix="rmtkit-bench-cache-") as cache:
        env = dict(os.environ, RMTKIT_CACHE=cache)
        for label in ("cold", "warm"):
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-c", _STARTUP_SCRIPT, name], env=env, capture_output=True,
                                  text=True, timeout=300)
            wall = time.perf_counter() - t0
            if proc.returncode != 0:
                raise RuntimeError(f"{label}-start subprocess failed: {proc.stderr.strip()[-2000:]}")
            rec = json.loads(proc.stdout.strip().splitlines()[-1])
            rec["subprocess_wall_s"] = wall  # includes interpreter start-up and imports
            out[label] = rec
    return out


# ---- 5. peers ----------------------------------------------------------------------------
def bench_peers(robot, n_loop: int, single_calls: int) -> dict:
    chain = robot.chain
    out: dict = {}
    for key, module, make in (("pinocchio", "pinocchio", pinocchio_loops), ("roboticstoolbox", "roboticstoolbox",
                                                                            rtb_loops)):
        mod, why = _try_import(module)
        if mod is None:
            out[key] = {"skipped": why}
            continue
        Q = robot.random_configurations(n_loop, seed=SEED + 3)
        loops = make(chain, Q)
        loops.fk_j_manip()
        with ForeignLoad() as load:
            rec = {"version": mod.__version__, "configs": n_loop,
                   "loop_fk_j_manip": _stats(_time_repeat(loops.fk_j_manip, 3), n_loop),
                   "loop_fk_j": _stats(_time_repeat(loops.fk_j, 3), n_loop),
                   "single_fk_j": _latency_us(loops.single_fk_j, single_calls, 5)}
            if loops.fk_batch is not None:
                loops.fk_batch()
                rec["batch_fk"] = _stats(_time_repeat(loops.fk_batch, 3), n_loop)
        rec["load"] = load.as_dict()
        out[key] = rec
    return out


# ---- 6. agreement ------------------------------------------------------------------------
def agreement(robot, count: int) -> dict:
    Q = robot.random_configurations(count, seed=SEED + 5)
    res, _ = robot.evaluate(Q, WANT_T | WANT_J | WANT_MANIP)
    T, J, manip = res["T"], res["J"], res["measures"][:, 0]
    out: dict = {"configs": count, "metric": "max |x - ref| / max(1, |ref|), elementwise"}
    fk = lambda X: robot.evaluate(X, WANT_T)[0]["T"]
    fd = {}
    for h in (1e-4, 1e-5, 1e-6):
        Jfd = fd_jacobian(fk, Q, h)
        fd[f"{h:g}"] = {"J_pos": _rel(J[:, :3], Jfd[:, :3]), "J_rot": _rel(J[:, 3:], Jfd[:, 3:])}
    best = min(fd, key=lambda k: max(fd[k].values()))
    out["finite_differences"] = {"steps": fd, "best_step": float(best), "J": max(fd[best].values())}
    pin, why = _try_import("pinocchio")
    Tp = Jp = None
    if pin is None:
        out["pinocchio"] = {"skipped": why}
    else:
        Tp, Jp = pinocchio_batch(robot.chain, Q)
        out["pinocchio"] = {"T": _rel(T, Tp), "J": _rel(J, Jp),
                            "manipulability": _rel(manip, np.abs(np.linalg.det(Jp)))}
    rtb, why = _try_import("roboticstoolbox")
    if rtb is None:
        out["roboticstoolbox"] = {"skipped": why}
    else:
        Tr, Jr = rtb_batch(robot.chain, Q)
        out["roboticstoolbox"] = {"T": _rel(T, Tr), "J": _rel(J, Jr)}
        if Tp is not None:
            out["pinocchio_vs_rtb"] = {"T": _rel(Tp, Tr), "J": _rel(Jp, Jr)}
    return out


# ---- targets and the whole run -----------------------------------------------------------
def _check(key: str, value) -> dict:
    desc, op, thr, unit = TARGETS[key]
    if value is None or (isinstance(value, float) and math.isnan(value)):
        status = "SKIP"
    else:
        status = "PASS" if (value >= thr if op == ">=" else value <= thr) else "MISS"
    return {"key": key, "what": desc, "value": value, "target": f"{op} {thr:g} {unit}".strip(), "status": status}


def _ratios(batch: dict, single: dict, peers: dict, n_all: int) -> dict:
    """rmtkit / peer, like with like (1 thread vs 1 thread, single call vs single call)."""
    one = batch["threads"]["1"]["100000"]["out"]["median_cfg_per_s"]
    ratios = {}
    for key in ("pinocchio", "roboticstoolbox"):
        p = peers.get(key, {})
        if "loop_fk_j_manip" not in p:
            continue
        ratios[f"batch_fk_j_manip_1thread_vs_{key}_loop"] = one / p["loop_fk_j_manip"]["median_cfg_per_s"]
        ratios[f"single_fk_jacobian_{key}_us_over_rmtkit_us"] = (p["single_fk_j"]["median_us"]
                                                                 / single["fk_jacobian"]["median_us"])
    if str(n_all) in batch["threads"] and n_all != 1:
        ratios[f"rmtkit_{n_all}threads_over_1thread"] = (
            batch["threads"][str(n_all)]["100000"]["out"]["median_cfg_per_s"] / one)
    return ratios


def run(name: str, quick: bool, log=None) -> dict:
    say = log or (lambda msg: None)
    t_start = time.perf_counter()
    sizes = [100_000] if quick else [100_000, 1_000_000]
    repeats = 3 if quick else 5
    single_calls = 5_000 if quick else 20_000
    n_all = default_threads()
    thread_counts = sorted({1, n_all})

    with ForeignLoad() as load_all:
        say("start-up (cold, warm) in subprocesses ...")
        with ForeignLoad() as load_startup:
            startup = bench_startup(name)
        startup["load"] = load_startup.as_dict()
        robot = kin.load_robot(name)
        say(f"batch ({', '.join(f'{n:g}' for n in sizes)}; threads {thread_counts}) ...")
        batch = bench_batch(robot, sizes, repeats, thread_counts)
        say("loaded case (a second busy process) ...")
        loaded = bench_loaded(robot, thread_counts, 4.0 if quick else 10.0)
        say("single-call latency ...")
        with ForeignLoad() as load_single:
            single = bench_single(robot, single_calls, 5)
        single["load"] = load_single.as_dict()
        say("peers ...")
        peers = bench_peers(robot, 5_000 if quick else 20_000, single_calls)
        say("agreement ...")
        agree = agreement(robot, 50 if quick else 200)

    ratios = _ratios(batch, single, peers, n_all)
    all_rec = batch["threads"][str(n_all)]["100000"]["out"]["median_cfg_per_s"]
    l5 = loaded["sizes"]["100000"]
    agp, agr = agree.get("pinocchio", {}), agree.get("roboticstoolbox", {})
    targets = [
        _check("batch_all_threads", all_rec),
        _check("single_fk_jacobian_us", single["fk_jacobian"]["median_us"]),
        _check("loaded_all_vs_1_thread", l5[str(n_all)]["median_cfg_per_s"] / l5["1"]["median_cfg_per_s"]
               if n_all > 1 else None),
        _check("cold_start_s", startup["cold"]["total_s"] if not startup["cold"]["cached"] else float("nan")),
        _check("warm_start_s", startup["warm"]["total_s"] if startup["warm"]["cached"] else float("nan")),
        _check("agreement_pinocchio", max(agp["T"], agp["J"]) if "T" in agp else None),
        _check("agreement_rtb", max(agr["T"], agr["J"]) if "T" in agr else None),
    ]
    unreliable = [k for k, d in (("start-up", startup["load"]), ("single", single["load"]),
                                 *((f"batch {t} thread(s)", r["load"]) for t, r in batch["threads"].items()),
                                 *((f"peer {k}", p["load"]) for k, p in peers.items() if "load" in p))
                  if not d["reliable"]]
    import casadi
    return {
        "benchmark": "bench_kin",
        "robot": name,
        "quick": quick,
        "environment": {"python": platform.python_version(), "numpy": np.__version__, "casadi": casadi.__version__,
                        "machine": platform.machine(), "cpu_count": os.cpu_count(), "threads_all": n_all,
                        "backend": robot.backend, "arch": getattr(robot.evaluator, "arch", None),
                        "single_call_extension": getattr(robot.evaluator, "single", None) is not None,
                        "RMTKIT_THREADS": os.environ.get("RMTKIT_THREADS", "(unset: the CPUs this process may use)"),
                        "load": load_all.as_dict(), "unreliable_sections": unreliable},
        "batch": batch,
        "loaded": loaded,
        "single": single,
        "startup": startup,
        "peers": peers,
        "ratios": ratios,
        "agreement": agree,
        "targets": targets,
        "elapsed_s": time.perf_counter() - t_start,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m studies.benchmarks.bench_kin", description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object with all figures instead of the table")
    ap.add_argument("--robot", default=DEFAULT_ROBOT, help=f"bundled 6-joint arm (default {DEFAULT_ROBOT}; "
                                                             "e.g. ur5e, puma560)")
    ap.add_argument("--quick", action="store_true", help="N = 1e5 only, fewer repeats (smoke test)")
    args = ap.parse_args(argv)
    if args.robot not in kin.bundled_robots():
        ap.error(f"unknown robot {args.robot!r}; bundled: {', '.join(kin.bundled_robots())}")
    n = kin.load_chain(args.robot).n
    if n != 6:
        ap.error(f"{args.robot} has {n} joints; this benchmark is for 6-joint arms")
    return measure_and_print("bench_kin", args.json,
                             lambda log: run(args.robot, args.quick, log), format_report)


if __name__ == "__main__":
    sys.exit(main())
