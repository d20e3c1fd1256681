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
   from the chain's DH table (:func:`pinocchio_model`, :func:`rtb_robot`);
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


# ---- small numpy transforms (independent of kin.transforms) ----------------------------------
def _rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]])


def _tx(x: float) -> np.ndarray:
    T = np.eye(4)
    T[0, 3] = x
    return T


def _tz(z: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = z
    return T


def dh_pre_post(joint_type: str, convention: str, a: float, alpha: float, d: float, theta: float):
    """Split one DH row into fixed transforms around the joint's own motion: A_i = pre · M(q) · post.

    M(q) is Rz(q) (revolute) or Tz(q) (prismatic), the motion of a pinocchio RZ / PZ joint.

    * standard:  A = Rz(θ)·Tz(d)·Tx(a)·Rx(α)
        revolute  θ = q + theta:  pre = Rz(theta),        post = Tz(d)·Tx(a)·Rx(α)
                                  (Rz(q) and Tz(d) commute)
        prismatic d = q + d:      pre = Rz(theta)·Tz(d),  post = Tx(a)·Rx(α)
    * modified:  A = Rx(α)·Tx(a)·Rz(θ)·Tz(d)   (the row holds a_{i-1}, α_{i-1})
        revolute:                 pre = Rx(α)·Tx(a)·Rz(theta),        post = Tz(d)
        prismatic:                pre = Rx(α)·Tx(a)·Rz(theta)·Tz(d),  post = I
    """
    if convention == "standard":
        if joint_type == "revolute":
            return _rz(theta), _tz(d) @ _tx(a) @ _rx(alpha)
        return _rz(theta) @ _tz(d), _tx(a) @ _rx(alpha)
    if convention == "modified":
        head = _rx(alpha) @ _tx(a) @ _rz(theta)
        if joint_type == "revolute":
            return head, _tz(d)
        return head @ _tz(d), np.eye(4)
    raise ValueError(f"convention {convention!r} unknown")


def _segments(chain):
    """Per joint (type, pre, post) from the chain's numeric DH table."""
    table = chain.dh_table()
    return [(j.type, *dh_pre_post(j.type, chain.convention, *row)) for j, row in zip(chain.joints, table)]


# ---- peer models ---------------------------------------------------------------------------
def pinocchio_model(chain):
    """A ``pin.Model`` of the chain, joint by joint, plus the id of an operational frame at the tool.

    Joint i's placement in its parent joint's frame is post_{i-1} · pre_i (post_0 = base), so that
    pinocchio's joint frame i is base · A_1 ⋯ A_{i-1} · pre_i · M(q_i); the tool frame sits at
    post_n · tool in the last joint's frame.  World frame = rmtkit's base (reference) frame.
    """
    import pinocchio as pin

    model = pin.Model()
    model.name = chain.name
    parent, carry = 0, chain.base.matrix
    for i, ((jtype, pre, post), (lo, hi)) in enumerate(zip(_segments(chain), chain.limits), 1):
        jm = pin.JointModelRZ() if jtype == "revolute" else pin.JointModelPZ()
        big = np.array([1e3])
        parent = model.addJoint(parent, jm, pin.SE3(carry @ pre), f"joint{i}", big, big,
                                np.array([lo]), np.array([hi]))
        carry = post
    fid = model.addFrame(pin.Frame("tool", parent, 0, pin.SE3(carry @ chain.tool.matrix), pin.FrameType.OP_FRAME))
    return model, fid


def pinocchio_fk_jacobian(model, data, fid, q):
    """(T 4×4, J 6×n) at the tool frame; J in LOCAL_WORLD_ALIGNED (rows vx vy vz wx wy wz)."""
    import pinocchio as pin

    pin.computeJointJacobians(model, data, q)  # includes forward kinematics
    J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)  # updates oMf[fid]
    return data.oMf[fid].homogeneous, J


def rtb_robot(chain):
    """A ``roboticstoolbox.DHRobot`` of the chain (standard or modified links, offsets, base, tool)."""
    import roboticstoolbox as rtb
    from spatialmath import SE3

    links = []
    mod = chain.convention == "modified"
    for j, (a, alpha, d, theta), (lo, hi) in zip(chain.joints, chain.dh_table(), chain.limits):
        qlim = [lo, hi]
        if j.type == "revolute":
            cls = rtb.RevoluteMDH if mod else rtb.RevoluteDH
            links.append(cls(d=d, a=a, alpha=alpha, offset=theta, qlim=qlim))
        else:
            cls = rtb.PrismaticMDH if mod else rtb.PrismaticDH
            links.append(cls(theta=theta, a=a, alpha=alpha, offset=d, qlim=qlim))
    return rtb.DHRobot(links, name=chain.name, base=SE3(chain.base.matrix, check=False),
                       tool=SE3(chain.tool.matrix, check=False))


def rtb_fk(robot, Q) -> np.ndarray:
    """Batch FK through ``robot.fkine(Q)`` → (N, 4, 4)."""
    T = robot.fkine(Q)
    return np.asarray(T.A).reshape(-1, 4, 4)


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


def _log_so3(R: np.ndarray) -> np.ndarray:
    """Rotation vectors of rotation matrices (..., 3, 3); robust for small angles (not near π)."""
    w = 0.5 * np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    s = np.linalg.norm(w, axis=-1)
    c = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    th = np.arctan2(s, c)
    k = np.where(s > 1e-300, th / np.where(s > 1e-300, s, 1.0), 1.0)
    return w * k[..., None]


def fd_jacobian(fk_batch, Q: np.ndarray, h: float, revolute: np.ndarray | None = None) -> np.ndarray:
    """Central-difference geometric Jacobian (N, 6, n) from a batch FK (M, n) → (M, 4, 4).

    Position rows: (p(q + h e_i) − p(q − h e_i)) / 2h; angular rows: log(R(q + h e_i) R(q − h e_i)ᵀ) / 2h.
    """
    N, n = Q.shape
    E = np.eye(n) * h
    Qp = (Q[:, None, :] + E[None]).reshape(-1, n)
    Qm = (Q[:, None, :] - E[None]).reshape(-1, n)
    Tp, Tm = fk_batch(Qp).reshape(N, n, 4, 4), fk_batch(Qm).reshape(N, n, 4, 4)
    J = np.empty((N, 6, n))
    J[:, :3, :] = ((Tp[..., :3, 3] - Tm[..., :3, 3]) / (2 * h)).transpose(0, 2, 1)
    W = _log_so3(Tp[..., :3, :3] @ Tm[..., :3, :3].swapaxes(-1, -2)) / (2 * h)
    J[:, 3:, :] = W.transpose(0, 2, 1)
    return J


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
        model, fid = pinocchio_model(chain)
        data = model.createData()
        Q = robot.random_configurations(n_pin, seed=SEED + 3)
        LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        det = np.linalg.det
        cjj, gfj = pin.computeJointJacobians, pin.getFrameJacobian
        oMf = data.oMf

        def loop_full():
            res = np.empty(n_pin)
            for k in range(n_pin):
                cjj(model, data, Q[k])
                J = gfj(model, data, fid, LWA)
                oMf[fid].homogeneous
                res[k] = abs(det(J))
            return res

        def loop_fkj():
            for k in range(n_pin):
                cjj(model, data, Q[k])
                gfj(model, data, fid, LWA)
                oMf[fid].homogeneous

        loop_full()
        q0 = Q[0]
        out["pinocchio"] = {
            "version": pin.__version__,
            "configs": n_pin,
            "loop_fk_j_manip": _stats(_time_repeat(loop_full, 3), n_pin),
            "loop_fk_j": _stats(_time_repeat(loop_fkj, 3), n_pin),
            "single_fk_j": _latency_us(lambda: (cjj(model, data, q0), gfj(model, data, fid, LWA),
                                                oMf[fid].homogeneous), single_calls, 5),
        }
    rtb, why = _try_import("roboticstoolbox")
    if rtb is None:
        out["roboticstoolbox"] = {"skipped": why}
    else:
        r = rtb_robot(chain)
        Q = robot.random_configurations(n_rtb, seed=SEED + 4)
        rtb_fk(r, Q[:10])
        jac = r.jacob0

        def jloop():
            for k in range(n_rtb):
                jac(Q[k])

        jloop()
        out["roboticstoolbox"] = {
            "version": rtb.__version__,
            "configs": n_rtb,
            "fkine_batch": _stats(_time_repeat(lambda: rtb_fk(r, Q), 3), n_rtb),
            "jacob0_loop": _stats(_time_repeat(jloop, 3), n_rtb),
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
        model, fid = pinocchio_model(robot.chain)
        data = model.createData()
        pairs = [pinocchio_fk_jacobian(model, data, fid, q) for q in Q]
        Tp = np.array([p[0] for p in pairs])
        Jp = np.array([p[1] for p in pairs])
        out["pinocchio"] = {"T": _rel(T, Tp), "J": _rel(J, Jp),
                            "manipulability": _rel(manip, np.abs(np.linalg.det(Jp)))}
    rtb, why = _try_import("roboticstoolbox")
    if rtb is None:
        out["roboticstoolbox"] = {"skipped": why}
    else:
        r = rtb_robot(robot.chain)
        Tr = rtb_fk(r, Q)
        Jr = np.array([r.jacob0(q) for q in Q])
        out["roboticstoolbox"] = {"T": _rel(T, Tr), "J": _rel(J, Jr)}
        if Tp is not None:
            out["pinocchio_vs_rtb"] = {"T": _rel(Tp, Tr), "J": _rel(Jp, Jr)}
    return out


# ---- report ------------------------------------------------------------------------------
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


def _fmt_rate(x: float) -> str:
    return f"{x / 1e6:8.3f} M/s"


def format_report(R: dict) -> str:
    L = []
    env = R["environment"]
    L.append(f"bench_kin — {R['robot']} ({env['backend']} backend; {env['cpu_count']} CPUs; "
             f"RMTKIT_THREADS={env['RMTKIT_THREADS']}; python {env['python']}, numpy {env['numpy']}, "
             f"casadi {env['casadi']}){' [quick]' if R['quick'] else ''}")
    L.append(f"load average (1 min) before / after: {env['loadavg_1min_before']:.2f} / {env['loadavg_1min_after']:.2f}"
             " — other processes on the machine distort every timing below")
    L.append("")
    L.append("1. batch FK + J(6x6) + manipulability, configurations/s (best / median)")
    for N, rec in R["batch"]["sizes"].items():
        pa = rec["public_alloc"]
        L.append(f"   N={int(N):>9,d}  robot.evaluate(Q, T|J|MANIP), allocates outputs : "
                 f"{_fmt_rate(pa['best_cfg_per_s'])} / {_fmt_rate(pa['median_cfg_per_s'])}  ({pa['repeats']} runs)")
        if "kernel_prealloc" in rec:
            kp = rec["kernel_prealloc"]
            L.append(f"   N={int(N):>9,d}  kernel into preallocated buffers (private entry) : "
                     f"{_fmt_rate(kp['best_cfg_per_s'])} / {_fmt_rate(kp['median_cfg_per_s'])}"
                     f"  (same numbers: {kp['matches_public']})")
            L.append(f"   {'':13s}  alloc + first touch of outputs alone {rec['alloc_first_touch_s'] * 1e3:7.1f} ms; "
                     f"input check (as_batch) {rec['as_batch_check_s'] * 1e3:6.1f} ms; "
                     f"public median {pa['median_s'] * 1e3:7.1f} ms vs kernel {kp['median_s'] * 1e3:7.1f} ms")
    v = R["batch_variants_100000"]
    L.append("   N=  100,000  public call, other outputs (median): " +
             ", ".join(f"{k} {_fmt_rate(s['median_cfg_per_s']).strip()}" for k, s in v.items()))
    L.append("")
    s = R["single"]
    L.append("2. single call, µs (best / median)")
    for k, lab in (("fk_jacobian", "robot.fk_jacobian(q)"), ("fk", "robot.fk(q)"),
                   ("kernel_one_T|J", "evaluator.one(q, T|J) (C call only)")):
        if k in s:
            L.append(f"   {lab:38s} {s[k]['best_us']:7.2f} / {s[k]['median_us']:7.2f}   ({s[k]['calls']} calls x {s[k]['repeats']})")
    L.append("")
    L.append("3. start-up, s (inside a fresh subprocess, after imports; fresh RMTKIT_CACHE)")
    for k in ("cold", "warm"):
        r = R["startup"][k]
        L.append(f"   {k:4s} total {r['total_s']:7.3f}  = load_chain {r['load_chain_s']:.3f} + symbolic "
                 f"{r['symbolic_s']:.3f} + evaluator {r['evaluator_s']:.3f} + first fk {r['first_fk_s']:.4f}"
                 f"   (cached={r['cached']}, backend={r['backend']}; subprocess wall incl. imports "
                 f"{r['subprocess_wall_s']:.2f})")
        if "codegen_again_s" in r:
            L.append(f"        (C code generation + hashing alone, re-run afterwards: {r['codegen_again_s']:.3f})")
    L.append("")
    L.append("4. peers")
    p = R["peers"]
    if "skipped" in p["pinocchio"]:
        L.append(f"   pinocchio: skipped — {p['pinocchio']['skipped']}")
    else:
        pp = p["pinocchio"]
        L.append(f"   pinocchio {pp['version']}, Python loop over {pp['configs']:,d} configurations (best / median):")
        L.append(f"     FK + frame Jacobian + |det J|  {_fmt_rate(pp['loop_fk_j_manip']['best_cfg_per_s'])} / "
                 f"{_fmt_rate(pp['loop_fk_j_manip']['median_cfg_per_s'])}")
        L.append(f"     FK + frame Jacobian            {_fmt_rate(pp['loop_fk_j']['best_cfg_per_s'])} / "
                 f"{_fmt_rate(pp['loop_fk_j']['median_cfg_per_s'])}")
        L.append(f"     single FK + J call, µs         {pp['single_fk_j']['best_us']:7.2f} / {pp['single_fk_j']['median_us']:7.2f}")
    if "skipped" in p["roboticstoolbox"]:
        L.append(f"   roboticstoolbox: skipped — {p['roboticstoolbox']['skipped']}")
    else:
        rr = p["roboticstoolbox"]
        L.append(f"   roboticstoolbox {rr['version']}, {rr['configs']:,d} configurations (best / median):")
        L.append(f"     fkine(Q) batch                 {_fmt_rate(rr['fkine_batch']['best_cfg_per_s'])} / "
                 f"{_fmt_rate(rr['fkine_batch']['median_cfg_per_s'])}")
        L.append(f"     jacob0(q) loop                 {_fmt_rate(rr['jacob0_loop']['best_cfg_per_s'])} / "
                 f"{_fmt_rate(rr['jacob0_loop']['median_cfg_per_s'])}")
    if R["ratios"]:
        L.append("   ratios rmtkit / peer (medians; rmtkit public batch call at N=1e5, multi-threaded, "
                 "against single-threaded Python loops of the peers):")
        for k, x in R["ratios"].items():
            L.append(f"     {k:50s} {x:10.1f}x")
    L.append("")
    a = R["agreement"]
    L.append(f"5. agreement over {a['configs']} configurations ({a['metric']})")
    for k in ("pinocchio", "roboticstoolbox", "pinocchio_vs_rtb"):
        if k not in a:
            continue
        if "skipped" in a[k]:
            L.append(f"   rmtkit vs {k}: skipped")
        else:
            lab = "pinocchio vs rtb" if k == "pinocchio_vs_rtb" else f"rmtkit vs {k}"
            L.append(f"   {lab:28s} " + "  ".join(f"{m} {x:.2e}" for m, x in a[k].items()))
    fd = a["finite_differences"]
    L.append("   rmtkit J vs central FD of rmtkit FK: " +
             "; ".join(f"h={h}: pos {d['J_pos']:.1e}, rot {d['J_rot']:.1e}" for h, d in fd["steps"].items()) +
             f"  (best h={fd['best_step']:g}: {fd['J']:.1e}; step-size limited, no target)")
    L.append("")
    L.append("targets")
    for t in R["targets"]:
        v = t["value"]
        vs = "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.4g}"
        L.append(f"   {t['status']:4s}  {t['what']:40s} {vs:>12s}   target {t['target']}")
    L.append(f"\n(elapsed {R['elapsed_s']:.1f} s)")
    return "\n".join(L)


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
