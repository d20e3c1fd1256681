"""Text report of the kinematics benchmark: the result of :func:`bench_kin.run` as a table.

:func:`format_report` renders the dictionary that ``bench_kin --json`` prints (batch throughput,
single-call latency, start-up, peers and ratios, agreement, targets) as the human-readable report
that ``python -m studies.benchmarks.bench_kin`` prints without ``--json``.
"""
from __future__ import annotations

import math


def _fmt_rate(x: float) -> str:
    return f"{x / 1e6:8.3f} M/s"


def _load_note(d: dict) -> str:
    share = d.get("foreign_cpu_share")
    txt = (f"other processes {share * 100:.0f} % of the CPUs" if share is not None
           else f"load average {d['loadavg_1min_before']:.2f}")
    return txt if d["reliable"] else f"UNRELIABLE: {txt}"


def _rates(st: dict) -> str:
    return f"{_fmt_rate(st['best_cfg_per_s'])} / {_fmt_rate(st['median_cfg_per_s'])}"


def format_report(R: dict) -> str:
    L = []
    env = R["environment"]
    L.append(f"bench_kin — {R['robot']} ({env['backend']} backend, {env['arch']} build, single-call extension "
             f"{env['single_call_extension']}; {env['cpu_count']} CPUs, {env['threads_all']} usable; "
             f"RMTKIT_THREADS={env['RMTKIT_THREADS']}; python {env['python']}, numpy {env['numpy']}, "
             f"casadi {env['casadi']}){' [quick]' if R['quick'] else ''}")
    L.append(f"machine load over the whole run: {_load_note(env['load'])}; load average before / after "
             f"{env['load']['loadavg_1min_before']:.2f} / {env['load']['loadavg_1min_after']:.2f}")
    if env["unreliable_sections"]:
        L.append("UNRELIABLE figures (other processes took > 10 % of the CPUs meanwhile): "
                 + ", ".join(env["unreliable_sections"]))
    L.append("")
    L.append("1. batch FK + J(6x6) + manipulability, configurations/s (best / median)")
    for th, rec in R["batch"]["threads"].items():
        L.append(f"   {th} thread(s)  [{_load_note(rec['load'])}]")
        for N, r in rec.items():
            if N == "load":
                continue
            L.append(f"     N={int(N):>9,d}  allocating outputs {_rates(r['alloc'])}   into out= {_rates(r['out'])}"
                     f"   ({r['threads_ran']} ran)")
            if "sigma_min_out" in r:
                L.append(f"     N={int(N):>9,d}  sigma_min alone, into out= {_rates(r['sigma_min_out'])}")
    L.append("")
    ld = R["loaded"]
    L.append(f"2. loaded: a second process spinning on one CPU (bounded {ld['busy_process_bound_s']:g} s, "
             f"still running at the end: {ld['busy_process_still_running']}); FK+J+manip into out= (best / median)")
    for N, rec in ld["sizes"].items():
        L.append(f"     N={int(N):>9,d}  " + "   ".join(f"{th} thread(s) {_rates(st)}" for th, st in rec.items()))
    L.append("")
    s = R["single"]
    L.append(f"3. single call, µs (best / median)  [{_load_note(s['load'])}]")
    for k, lab in (("fk_jacobian", "robot.fk_jacobian(q)"), ("fk", "robot.fk(q)"), ("jacobian", "robot.jacobian(q)"),
                   ("measures", "robot.measures(q)"), ("extension_fk_jacobian", "evaluator.single.fk_jacobian(q) (C)")):
        if k in s:
            L.append(f"   {lab:38s} {s[k]['best_us']:7.3f} / {s[k]['median_us']:7.3f}   "
                     f"({s[k]['calls']} calls x {s[k]['repeats']})")
    L.append("")
    L.append("4. start-up, s (inside a fresh subprocess, after imports; fresh RMTKIT_CACHE)")
    for k in ("cold", "warm"):
        r = R["startup"][k]
        L.append(f"   {k:4s} total {r['total_s']:7.3f}  = load_chain {r['load_chain_s']:.3f} + symbolic "
                 f"{r['symbolic_s']:.3f} + evaluator {r['evaluator_s']:.3f} + first fk {r['first_fk_s']:.4f}"
                 f"   (cached={r['cached']}, backend={r['backend']}; subprocess wall incl. imports "
                 f"{r['subprocess_wall_s']:.2f})")
        if "codegen_again_s" in r:
            L.append(f"        (generated header alone, re-run afterwards: {r['codegen_again_s']:.3f})")
    L.append("")
    L.append("5. peers, one thread, the fast way each documents (best / median)")
    for key, p in R["peers"].items():
        if "skipped" in p:
            L.append(f"   {key}: skipped — {p['skipped']}")
            continue
        how = ("computeFrameJacobian(LOCAL_WORLD_ALIGNED) + frame placement" if key == "pinocchio"
               else "C++ ETS: ets.eval(q) + ets.jacob0(q); batch ets.eval(Q)")
        L.append(f"   {key} {p['version']} — {how}; loop over {p['configs']:,d} configurations  "
                 f"[{_load_note(p['load'])}]")
        L.append(f"     FK + J + |det J|   {_rates(p['loop_fk_j_manip'])}")
        L.append(f"     FK + J             {_rates(p['loop_fk_j'])}")
        if "batch_fk" in p:
            L.append(f"     FK, one batch call {_rates(p['batch_fk'])}")
        L.append(f"     single FK + J, µs  {p['single_fk_j']['best_us']:7.3f} / {p['single_fk_j']['median_us']:7.3f}")
    if R["ratios"]:
        L.append("   ratios (medians; like with like: rmtkit 1 thread into out= vs the peers' 1-thread loops, "
                 "single call vs single call):")
        for k, x in R["ratios"].items():
            L.append(f"     {k:55s} {x:10.2f}x")
    L.append("")
    a = R["agreement"]
    L.append(f"6. agreement over {a['configs']} configurations ({a['metric']})")
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
