"""Kinematics benchmark: batch throughput, single-call latency, start-up, peers, agreement.

Run as ``python -m studies.benchmarks.bench_kin [--json] [--robot NAME] [--quick]`` (part of
``make bench``).  For one 6-joint arm (default ``fanuc_m16ib20``) it measures

1. batch FK + 6×6 Jacobian + manipulability throughput (configurations/s) at N = 1e5 and 1e6,
   through the public call ``robot.evaluate(Q, WANT_T | WANT_J | WANT_MANIP)`` (which allocates
   its outputs) and, separately labelled, through the compiled kernel writing into preallocated
   buffers (the evaluator's private ctypes entry — there is no public into-buffer API);
2. single-call latency of ``robot.fk_jacobian(q)`` and ``robot.fk(q)`` (µs, timeit);
3. cold start (compile into an empty cache) and warm start (load from that cache), each in a fresh
   subprocess with its own temporary ``RMTKIT_CACHE``, timed inside the subprocess after the imports;
4. peers, when the optional ``bench`` extra is installed: pinocchio (a Python loop of
   FK + frame Jacobian + det) and roboticstoolbox-python (batch ``fkine``, ``jacob0`` loop), built
   from the chain's DH table (:mod:`studies.benchmarks.peers`);
5. agreement of T and J between rmtkit, pinocchio, roboticstoolbox and central finite differences.

Targets (checked with PASS/MISS): batch ≥ 2e6 configurations/s (median of the public call at the
largest N) and ≥ 10× the pinocchio loop; single FK+J ≤ 5 µs (median); cold start ≤ 15 s; warm
start ≤ 0.3 s; agreement with pinocchio and roboticstoolbox ≤ 1e-9.  A MISS does not change the
exit status (0); an error does.
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
from kin.compiled import WANT_J, WANT_MANIP, WANT_T, CompiledEvaluator
from studies.benchmarks.kin_report import format_report
from studies.benchmarks.peers import (
    fd_jacobian,
    pinocchio_batch,
    pinocchio_loops,
    rtb_batch,
    rtb_fk,
    rtb_loops,
)

DEFAULT_ROBOT = "fanuc_m16ib20"
SEED = 20240611

TARGETS = {
    # key: (description, comparison, threshold, unit)
    "batch_throughput": ("batch FK+J+manip, public call", ">=", 2e6, "cfg/s"),
    "batch_vs_pinocchio": ("batch / pinocchio loop (FK+J+manip)", ">=", 10.0, "x"),
    "single_fk_jacobian_us": ("single fk_jacobian(q)", "<=", 5.0, "us"),
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


# ---- 1. batch ----------------------------------------------------------------------------
def bench_batch(robot, sizes, repeats: int) -> dict:
    ev = robot.evaluator
    want = WANT_T | WANT_J | WANT_MANIP
    out = {"want": "T|J|MANIP", "sizes": {}}
    for N in sizes:
        Q = robot.random_configurations(N, seed=SEED)
        robot.evaluate(Q, want)  # warm-up (first touch of Q, thread pool start)
        rec = {"public_alloc": _stats(_time_repeat(lambda: robot.evaluate(Q, want), repeats), N)}
        if type(ev) is CompiledEvaluator:
            n = robot.n
            T, J, M = np.empty((N, 4, 4)), np.empty((N, 6, n)), np.empty((N, 4))
            P = ev.p1 if ev.n_p == 0 else np.ascontiguousarray(robot.chain.parameter_values)

            def into():
                ev._eval(Q.ctypes.data, P.ctypes.data, N, 0, T.ctypes.data, J.ctypes.data, M.ctypes.data,
                         want, ev.threads)

            into()  # first touch of the output pages
            rec["kernel_prealloc"] = _stats(_time_repeat(into, repeats), N)
            ref = robot.evaluate(Q[:1000], want)[0]
            rec["kernel_prealloc"]["matches_public"] = bool(np.array_equal(ref["T"], T[:1000])
                                                            and np.array_equal(ref["J"], J[:1000]))
            # where the public call's extra time goes: allocation + first touch of ~(16+6n+4)·8·N bytes
            def alloc_touch():
                a, b, c = np.empty((N, 4, 4)), np.empty((N, 6, n)), np.full((N, 4), np.nan)
                a.fill(0.0)
                b.fill(0.0)
                return c
            rec["alloc_first_touch_s"] = min(_time_repeat(alloc_touch, max(2, repeats // 2)))
            rec["as_batch_check_s"] = min(_time_repeat(lambda: robot.chain.as_batch(Q), max(2, repeats // 2)))
        out["sizes"][str(N)] = rec
    return out


def bench_batch_variants(robot, N: int, repeats: int) -> dict:
    """Public-call throughput for other output sets (for the peer ratios)."""
    Q = robot.random_configurations(N, seed=SEED + 1)
    out = {}
    for label, want in (("T", WANT_T), ("J", WANT_J), ("T|J", WANT_T | WANT_J)):
        robot.evaluate(Q, want)
        out[label] = _stats(_time_repeat(lambda: robot.evaluate(Q, want), repeats), N)
    return out


# ---- 2. single call ----------------------------------------------------------------------
def _latency_us(fn, number: int, repeat: int) -> dict:
    fn()
    per = [t / number * 1e6 for t in timeit.Timer(fn).repeat(repeat=repeat, number=number)]
    return {"best_us": min(per), "median_us": statistics.median(per), "calls": number, "repeats": repeat}


def bench_single(robot, number: int, repeat: int) -> dict:
    q = robot.random_configurations(1, seed=SEED + 2)[0]
    out = {"fk_jacobian": _latency_us(lambda: robot.fk_jacobian(q), number, repeat),
           "fk": _latency_us(lambda: robot.fk(q), number, repeat)}
    ev = robot.evaluator
    if type(ev) is CompiledEvaluator:  # the C call alone, for the wrapper's share of the latency
        out["kernel_one_T|J"] = _latency_us(lambda: ev.one(q, WANT_T | WANT_J), number, repeat)
    return out


# ---- 3. start-up -------------------------------------------------------------------------
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
    if hasattr(ev, "source"):
        s0 = time.perf_counter(); ev.source(); extra["codegen_again_s"] = time.perf_counter() - s0
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


# ---- 4. peers ----------------------------------------------------------------------------
def bench_peers(robot, n_pin: int, n_rtb: int, single_calls: int) -> dict:
    chain = robot.chain
    out: dict = {}
    pin, why = _try_import("pinocchio")
    if pin is None:
        out["pinocchio"] = {"skipped": why}
    else:
        Q = robot.random_configurations(n_pin, seed=SEED + 3)
        pl = pinocchio_loops(chain, Q)
        pl.fk_j_manip()
        out["pinocchio"] = {
            "version": pin.__version__,
            "configs": n_pin,
            "loop_fk_j_manip": _stats(_time_repeat(pl.fk_j_manip, 3), n_pin),
            "loop_fk_j": _stats(_time_repeat(pl.fk_j, 3), n_pin),
            "single_fk_j": _latency_us(pl.single_fk_j, single_calls, 5),
        }
    rtb, why = _try_import("roboticstoolbox")
    if rtb is None:
        out["roboticstoolbox"] = {"skipped": why}
    else:
        Q = robot.random_configurations(n_rtb, seed=SEED + 4)
        rl = rtb_loops(chain, Q)
        rtb_fk(rl.robot, Q[:10])
        rl.jacob0_loop()
        out["roboticstoolbox"] = {
            "version": rtb.__version__,
            "configs": n_rtb,
            "fkine_batch": _stats(_time_repeat(rl.fkine_batch, 3), n_rtb),
            "jacob0_loop": _stats(_time_repeat(rl.jacob0_loop, 3), n_rtb),
        }
    return out


# ---- 5. agreement ------------------------------------------------------------------------
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


def run(name: str, quick: bool, log=None) -> dict:
    say = log or (lambda msg: None)
    t_start = time.perf_counter()
    sizes = [100_000] if quick else [100_000, 1_000_000]
    repeats = 3 if quick else 5
    single_calls = 5_000 if quick else 20_000

    load0 = os.getloadavg()[0]
    say("start-up (cold, warm) in subprocesses ...")
    startup = bench_startup(name)

    robot = kin.load_robot(name)
    say(f"batch ({', '.join(f'{n:g}' for n in sizes)}) ...")
    batch = bench_batch(robot, sizes, repeats)
    variants = bench_batch_variants(robot, 100_000, repeats)
    say("single-call latency ...")
    single = bench_single(robot, single_calls, 5)
    say("peers ...")
    peers = bench_peers(robot, 5_000 if quick else 20_000, 500 if quick else 2_000, single_calls)
    say("agreement ...")
    agree = agreement(robot, 50 if quick else 200)

    top = batch["sizes"][str(sizes[-1])]["public_alloc"]["median_cfg_per_s"]
    b100k = batch["sizes"]["100000"]["public_alloc"]["median_cfg_per_s"]
    ratios = {}
    p = peers.get("pinocchio", {})
    if "loop_fk_j_manip" in p:
        ratios["batch_T|J|MANIP_vs_pinocchio_loop"] = b100k / p["loop_fk_j_manip"]["median_cfg_per_s"]
        ratios["batch_T|J_vs_pinocchio_loop_fk_j"] = (variants["T|J"]["median_cfg_per_s"]
                                                      / p["loop_fk_j"]["median_cfg_per_s"])
        ratios["single_fk_jacobian_latency_pinocchio_over_rmtkit"] = (
            p["single_fk_j"]["median_us"] / single["fk_jacobian"]["median_us"])
    r = peers.get("roboticstoolbox", {})
    if "fkine_batch" in r:
        ratios["batch_T_vs_rtb_fkine"] = variants["T"]["median_cfg_per_s"] / r["fkine_batch"]["median_cfg_per_s"]
        ratios["batch_J_vs_rtb_jacob0_loop"] = variants["J"]["median_cfg_per_s"] / r["jacob0_loop"]["median_cfg_per_s"]

    agp = agree.get("pinocchio", {})
    agr = agree.get("roboticstoolbox", {})
    targets = [
        _check("batch_throughput", top),
        _check("batch_vs_pinocchio", ratios.get("batch_T|J|MANIP_vs_pinocchio_loop")),
        _check("single_fk_jacobian_us", single["fk_jacobian"]["median_us"]),
        _check("cold_start_s", startup["cold"]["total_s"] if not startup["cold"]["cached"] else float("nan")),
        _check("warm_start_s", startup["warm"]["total_s"] if startup["warm"]["cached"] else float("nan")),
        _check("agreement_pinocchio", max(agp["T"], agp["J"]) if "T" in agp else None),
        _check("agreement_rtb", max(agr["T"], agr["J"]) if "T" in agr else None),
    ]
    import casadi
    return {
        "benchmark": "bench_kin",
        "robot": name,
        "quick": quick,
        "environment": {"python": platform.python_version(), "numpy": np.__version__, "casadi": casadi.__version__,
                        "machine": platform.machine(), "cpu_count": os.cpu_count(), "backend": robot.backend,
                        "loadavg_1min_before": load0, "loadavg_1min_after": os.getloadavg()[0],
                        "RMTKIT_THREADS": os.environ.get("RMTKIT_THREADS", "(unset: 0 = all cores)")},
        "batch": batch,
        "batch_variants_100000": variants,
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
    log = None if args.json else (lambda msg: print(msg, file=sys.stderr, flush=True))
    try:
        R = run(args.robot, args.quick, log)
    except Exception as e:  # a failed measurement is an error, not a MISS
        print(f"bench_kin: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    print(json.dumps(R, indent=None if args.json else 2, default=float) if args.json else format_report(R))
    return 0


if __name__ == "__main__":
    sys.exit(main())
