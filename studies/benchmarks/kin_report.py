"""Text report of the kinematics benchmark: the result of :func:`bench_kin.run` as a table.

:func:`format_report` renders the dictionary that ``bench_kin --json`` prints (batch throughput,
single-call latency, start-up, peers and ratios, agreement, targets) as the human-readable report
that ``python -m studies.benchmarks.bench_kin`` prints without ``--json``.
"""
from __future__ import annotations

import math


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
