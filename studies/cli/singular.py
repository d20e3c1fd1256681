"""``rmt singularities``, ``rmt windows`` and ``rmt workspace``: the singular set, its windows and
the (functional) workspace of a robot."""
from __future__ import annotations

import kin
from kin.display import joint_value
from studies.cli.common import (
    MAX_SIGMA,
    CliInputError,
    bounded,
    output_file,
    seed,
    window_width_args,
    windows_from_args,
)
from studies.jsonio import dump
from studies.taskrows import require_task_rows
from studies.units import joint_value_to_file

#: the most joint-space samples ``rmt workspace`` takes
MAX_SAMPLES = 10_000_000


def _analyse(robot, args):
    from kin.singular import analyse_singularities
    from studies.cli.progress import TerminalProgress
    budget = {} if args.exact_timeout is None else {"exact_timeout": args.exact_timeout}
    with TerminalProgress() as progress:
        return analyse_singularities(robot, seed=args.seed, progress=progress, **budget)


def cmd_singularities(args, load_robot) -> int:
    robot = require_task_rows(load_robot(args.robot))
    analysis = _analyse(robot, args)
    from studies.study.singular import singularities_json
    out = singularities_json(robot, analysis)
    if args.json:
        print(dump(out))
        return 0
    c = robot.chain
    print(f"{c.name}: {len(out['factors'])} singular factor{'s' if len(out['factors']) != 1 else ''} "
          f"({analysis.method}: {analysis.derivation}; {analysis.seconds:.2f} s)")
    for i, f in enumerate(out["factors"], 1):
        joints = ", ".join(f"q{j}" for j in f["joints"])
        mult = f" (multiplicity {f['multiplicity']})" if f["multiplicity"] > 1 else ""
        print(f"\n{i}. [{f['kind']}] {f['expr']} = 0{mult}")
        if f["symbolic"] != f["expr"]:
            print(f"   symbolic: {f['symbolic']}")
        print(f"   joints: {joints} — {f['meaning']}")
        sol = f["solutions"]
        if sol["type"] == "values":
            j = sol["joint"]
            unit = c.angle_unit if c.joints[j - 1].is_revolute else c.length_unit
            vals = ", ".join(f"{v:.6g}" for v in sol["values_file_units"]) or "none inside the limits"
            print(f"   q{j} ∈ {{{vals}}} {unit}"
                  + (f"   (exact, rad/m: {', '.join(sol['exact'])})" if sol["exact"] else ""))
        else:
            rng = ", ".join(f"{k} ∈ [{r[0]:.4g}, {r[1]:.4g}]" for k, r in sol["ranges_file_units"].items() if r)
            print(f"   a manifold: {sol['count']} sampled configurations inside the limits; {rng}")
    return 0


def _width(c, w, v: float | None = None) -> str:
    """A window's half-width (or another joint-space distance ``v`` of it: rad where a revolute joint
    takes part, else m) in the robot file's unit, named: "5°", "2 mm"."""
    j = next((j - 1 for j in w.joints if c.joints[j - 1].is_revolute), w.joints[0] - 1)
    return joint_value(c, j, w.width if v is None else v)


def _windows_text(robot: kin.Robot, ws) -> str:
    c = robot.chain
    lines = [f"{c.name}: {len(ws.windows)} window{'s' if len(ws.windows) != 1 else ''}"]
    for w in ws.windows:
        if w.is_interval:
            j = w.joints[0]
            unit = c.angle_unit if c.joints[j - 1].is_revolute else c.length_unit
            ivs = " ∪ ".join(f"[{joint_value_to_file(c, j, lo):.6g}, {joint_value_to_file(c, j, hi):.6g}]"
                             for lo, hi in w.intervals)
            lines.append(f"  {w.name}\n      q{j} ∈ {ivs or '∅'} {unit}   (half-width {_width(c, w)}, {w.method})")
        elif getattr(w, "is_point_set", False):
            lines.append(f"  {w.name}\n      within {_width(c, w)} of {len(w.points)} sampled points   ({w.method})")
            miss = w.detail.get("miss") or {}
            if miss.get("fresh_set_points"):
                lines.append(f"      sampled: {miss['outside_window']} of {miss['fresh_set_points']} "
                             "fresh points of the "
                             f"set lie outside it (farthest {_width(c, w, miss['largest_distance'])} from a sample)")
        else:
            lines.append(f"  {w.name}\n      |g(q)| ≤ {w.epsilon:.6g} (SI)   (half-width ≥ {_width(c, w)}, {w.method})")
    floor = next((w.detail["floor"] for w in ws.windows if isinstance(w.detail.get("floor"), dict)), None)
    if floor:
        lines.append(f"  {floor['measure']} ≥ {floor['threshold']:g} outside the windows is sampled, not proven: "
                     f"{floor['below_threshold_outside']} of the {floor['outside_windows']} fresh configurations "
                     f"outside them (of {floor['fresh_samples']} drawn) fall below")
    if any(getattr(w, "is_point_set", False) for w in ws.windows):
        lines.append("  point-set windows are sampled: they hold the set as far as its samples show; a path is proven "
                     "clear of them as they are, not of what they miss (a σ_min floor proves that)")
    return "\n".join(lines)


def cmd_windows(args, load_robot) -> int:
    output_file(args.out)
    robot = require_task_rows(load_robot(args.robot))
    c = robot.chain
    reports = None
    if not args.learned:     # as plan and check-path build them, whatever --seed says
        ws = windows_from_args(robot, args.margin, args.sigma_min, args.exact_timeout)
    else:
        analysis = _analyse(robot, args)
        if analysis.method != "exact":
            raise CliInputError(f"--learned needs the exact singular factors; the exact analysis of {c.name} did not "
                                f"finish within --exact-timeout {args.exact_timeout:g} s (give more, or use "
                                "--margin or --sigma-min)")
        from design.learned.windows import jsonable_report, learned_windows
        from studies.published import compare_learned_window
        ws, reports = learned_windows(robot, analysis=analysis, seed=args.seed)
        reports = [jsonable_report(r) for r in reports]
        for r in reports:           # the published window beside ours, where one was published
            published = compare_learned_window(r, robot.name)
            if published is not None:
                r["published"] = published
    if args.out:
        ws.save(args.out)
    out = ws.to_dict()
    if reports is not None:
        out["learned"] = reports
    if args.json:
        print(dump(out))
        return 0
    print(_windows_text(robot, ws))
    for r in reports or []:
        t = r.get("published")
        if t:
            print(f"  published: {t['source']}; learned here: {t['joint']} half-width {t['ours_width']:.4g} rad "
                  f"({t['ours_over_published']:.1f}× the published {t['width']:g} rad)")
    if args.out:
        print(f"wrote {args.out}")
    return 0



def cmd_workspace(args, load_robot) -> int:
    from design.workspace import compute_workspace
    output_file(args.plot)
    robot = require_task_rows(load_robot(args.robot))
    ws = compute_workspace(robot, n_samples=args.samples, method=args.method, seed=args.seed,
                           threshold=args.sigma_min)
    if args.plot:
        from studies.plots import plot_workspace
        plot_workspace(ws, args.plot, title=f"{robot.chain.title or robot.name}: functional workspace")
    d = ws.to_dict()
    if args.json:
        print(dump(d))
        return 0
    c = robot.chain
    s = c.length_scale
    u = c.length_unit
    print(f"{c.name}: {d['counts']['samples']} samples ({d['sampling']['method']}, seed {args.seed}) "
          f"in {d['elapsed_s']:.2f} s")
    print(f"near-singular ({d['measure']['name']} < {d['measure']['threshold']:.4g} (SI), {d['measure']['rule']}): "
          f"{d['counts']['near_singular']} ({100 * d['counts']['near_singular_fraction']:.1f} %)")
    if d["volume"] is not None and d["area"] is None:
        print(f"volume ≈ {d['volume']:.4g} m³ (voxel {d['voxel']['size'] / s:.4g} {u}, {d['voxel']['occupied']} "
              f"occupied); functional volume ≈ {d['functional_volume']:.4g} m³")
    if d["area"] is not None:
        print(f"planar workspace: area ≈ {d['area']:.4g} m² (pixel {d['voxel']['size'] / s:.4g} {u}); "
              f"functional area ≈ {d['functional_area']:.4g} m²")
    print(f"reach {d['reach'] / s:.6g} {u} from the base origin, {d['radial_reach'] / s:.6g} {u} from the base z axis")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0


def _add_exact_timeout(sp) -> None:
    sp.add_argument("--exact-timeout", type=bounded(0, 3600, "s", open_low=True), metavar="S",
                    help="seconds for the exact (sympy) analysis before the numeric one answers (default: "
                         "kin.singular.DEFAULT_EXACT_TIMEOUT, 8 s; a finished one is cached on disk)")


def add_commands(add) -> None:
    """Register the commands with the CLI's ``add(name, func, help)`` helper."""
    sp = add("singularities", cmd_singularities, "the singular set: factors of det J, named, with their solutions")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("--seed", type=seed, default=0, help="seed of the zero-set samples (default 0)")
    _add_exact_timeout(sp)
    sp = add("windows", cmd_windows, "singular error windows around every factor of the singular set")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    g = window_width_args(sp, required=True, sigma_help="dexterity threshold: σ_min of the Jacobian in SI units "
                                                        "stays ≥ S outside the windows")
    g.add_argument("--learned", action="store_true",
                   help="learned-IK windows: widths from a learned IK model's error at singular poses")
    sp.add_argument("--out", metavar="FILE.json", help="save the windows (SI units) to a JSON file")
    sp.add_argument("--seed", type=seed, default=0,
                    help="seed of the learned model (default 0); margin and σ_min windows do not depend on it")
    _add_exact_timeout(sp)
    sp = add("workspace", cmd_workspace, "sampled workspace: volume, reach, near-singular share, plot")
    sp.add_argument("robot", metavar="ROBOT", help="bundled name or path to a robot .toml file")
    sp.add_argument("--samples", type=bounded(1, MAX_SAMPLES, "", integer=True), default=100_000,
                    help="number of joint-space samples (default 100000)")
    sp.add_argument("--method", default="sobol", choices=("sobol", "random", "grid"), help="sampling (default sobol)")
    sp.add_argument("--seed", type=seed, default=0, help="seed (default 0)")
    sp.add_argument("--sigma-min", type=bounded(0, MAX_SIGMA, "(SI)", open_low=True), metavar="S",
                    help="near-singular threshold on σ_min (SI; default: 5 %% of the median)")
    sp.add_argument("--plot", metavar="FILE.png", help="write top/front/side/isometric views")
