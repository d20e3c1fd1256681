"""Report sections that several studies share: the DH table, forward kinematics at configurations,
the singular set, windows, the workspace (four views and the 3-D view) and a planned path.

Each function writes into a :class:`~studies.study.context.Study` (inside the caller's
``with s.section(...)``), stores its numbers under ``s.results`` and returns what it computed so the
study can go on with it.  Values are shown in the robot file's units.
"""
from __future__ import annotations

import dataclasses
import tempfile
from pathlib import Path

import numpy as np

import kin
from studies.jointpath import path_csv_text
from studies.jsonio import jsonable
from studies.report.html import format_value
from studies.study import kinematics as ks
from studies.study.context import Study

__all__ = ["dh_table", "configurations_table", "singular_set", "windows_table", "workspace",
           "planned_path", "path_csv"]


def dh_table(s: Study, robot: kin.Robot, caption: str = "") -> None:
    """The robot's DH table in its file's units."""
    c = robot.chain
    lu, au = c.length_unit, c.angle_unit
    rows = []
    for r in ks.dh_rows(c):
        unit = au if r["type"] == "revolute" else lu
        rows.append([r["joint"], r["type"], r["a"], r["alpha"], r["d"], r["theta"],
                     f"{format_value(r['limits'][0])} … {format_value(r['limits'][1])} {unit}"])
    s.table(["joint", "type", f"a ({lu})", f"α ({au})", f"d ({lu})", f"θ ({au})", "limits"], rows,
            caption or f"{c.convention.capitalize()} DH parameters of `{c.name}` ({c.title}); a revolute joint adds "
                       f"its variable to θ, a prismatic joint to d.")
    s.results["robot"] = {"name": c.name, "title": c.title, "n": c.n, "convention": c.convention,
                          "units": {"length": lu, "angle": au}, "dh": ks.dh_rows(c)}


def configurations_table(s: Study, robot: kin.Robot, configs: list[tuple[str, list[float]]],
                         expected: dict[str, list[float]] | None = None, tol: float | None = None) -> list[dict]:
    """FK and dexterity at labelled configurations (file units).  ``expected`` maps a label to the
    reference tool position (file units); the table then shows the deviation and ``tol`` decides
    the check (a failed check is a finding with ok=False)."""
    c = robot.chain
    lu = c.length_unit
    out, rows = [], []
    for label, q in configs:
        r = {"label": label, **ks.evaluate_configuration(robot, q)}
        row = [label, ", ".join(f"{x:.4g}" for x in q), *r["position"], r["sigma_min"], r["manipulability"],
               "yes" if r["within_limits"] else "**no**"]
        if expected is not None:
            ref = expected.get(label)
            dev = None if ref is None else float(np.linalg.norm(np.subtract(r["position"], ref)))
            r["reference_position"], r["deviation"] = ref, dev
            r["matches_reference"] = None if dev is None else bool(dev <= (tol if tol is not None else 1e-9))
            row.append(dev)
        rows.append(row)
        out.append(r)
    header = ["configuration", "q (file units)", f"x ({lu})", f"y ({lu})", f"z ({lu})", "σ_min", "manipulability",
              "within limits"]
    if expected is not None:
        header.append(f"|p − reference| ({lu})")
    s.table(header, rows, "Tool position by forward kinematics; σ_min and manipulability of the task Jacobian "
                          f"in the robot file's units ({lu}/s and {c.angle_unit}/s per unit/s of each joint) "
                          "— 0 means singular.", fmt=".5g")
    s.results["configurations"] = jsonable(out)
    return out


def singular_set(s: Study, robot: kin.Robot, **options):
    """The singular set (factors with kinds) as a table; returns the analysis."""
    from kin.singular import analyse_singularities
    from studies.study.singular import singularities_json

    analysis = analyse_singularities(robot, **options)
    d = singularities_json(robot, analysis)
    rows = [[i, f"`{f['expr']}` = 0", f["kind"], ", ".join(f"q{j}" for j in f["joints"]), f["meaning"]]
            for i, f in enumerate(d["factors"], 1)]
    s.table(["#", "factor", "kind", "joints", "meaning"], rows,
            f"Singular set of `{robot.chain.name}`: {len(rows)} factor(s), found by the {d['method']} analysis "
            f"({d['derivation']}) in {d['seconds']:.2f} s.")
    s.results["singularities"] = d
    return analysis


def windows_table(s: Study, robot: kin.Robot, windows, label: str, caption: str = "", share_samples: int = 100_000,
                  key: str | None = None) -> dict:
    """The windows of a WindowSet (file units), with the share of the joint space each covers."""
    c = robot.chain
    Q = robot.random_configurations(share_samples, seed=0)
    rows, out = [], []
    for w in windows.windows:
        d = w.to_dict()
        j = w.joints[0]
        unit = c.angle_unit if c.joints[j - 1].is_revolute else c.length_unit
        scale = c.variable_scale[j - 1]
        if w.is_interval:
            where = " ∪ ".join(f"[{format_value(lo / scale)}, {format_value(hi / scale)}]"
                               for lo, hi in w.intervals) + f" {unit}"
            where = f"q{j} ∈ {where}"
        elif d.get("epsilon") is not None:
            where = f"|{w.expr}| ≤ {d['epsilon']:.3g}"
        else:
            where = f"within {w.width:.3g} of sampled points"
        share = float(np.mean(w.contains(Q)))
        d["share_of_joint_space"] = share
        rows.append([w.name, w.kind, where, w.width / scale if w.is_interval else w.width, share * 100 if share
                     is not None else None, _proof(w)])
        out.append(d)
    s.table(["window", "kind", "where", "half-width (file units)", "share of joint space (%)", "how it is known"],
            rows, caption or f"Windows ({label}).", fmt=".4g")
    floor = next((w.detail["floor"] for w in windows.windows if isinstance(w.detail.get("floor"), dict)), None)
    if floor:
        s.text(f"The widths come from a dexterity threshold ({floor['measure']} ≥ {floor['threshold']:g}), found by "
               f"sampling: the floor outside the windows is sampled, not proven. Of {floor['fresh_samples']} fresh "
               f"configurations, {floor['outside_windows']} lie outside every window, and "
               f"{floor['below_threshold_outside']} of those below the threshold.")
    total = float(np.mean(windows.contains(Q)))
    res = {"label": label, "windows": out, "share_of_joint_space": total}
    s.results.setdefault("windows", {})[key or label] = res
    return res


def _proof(w) -> str:
    """How a window is known, in a few words for a table."""
    proof = str(w.detail.get("proof", ""))
    if proof.startswith("exact"):
        return "exact roots"
    if proof == "interval bound":
        return f"proven: ε = width × {w.detail['grad_norm_bound']:.4g} (bound of ‖∇g‖)"
    if proof.startswith("sampled"):
        miss = w.detail.get("miss") or {}
        if miss.get("fresh_set_points"):
            return (f"sampled points: {miss['outside_window']} of {miss['fresh_set_points']} fresh points of the set "
                    "outside")
        return "sampled points"
    return "—"


def workspace(s: Study, robot: kin.Robot, samples: int, seed: int = 0, title: str = "", name: str = "workspace",
              q_view=None, path=None, targets=None, **options):
    """The sampled functional workspace: four views (PNG) and the interactive 3-D view; returns it."""
    from design.workspace import compute_workspace
    from studies.plots import plot_workspace
    from studies.report.view3d import robot_view

    s.input(f"{name}: samples", samples)
    s.input(f"{name}: seed", seed)
    ws = compute_workspace(robot, n_samples=samples, seed=seed, **options)
    with tempfile.TemporaryDirectory(prefix="rmt-fig-") as tmp:
        p = Path(tmp) / "figure.png"
        plot_workspace(ws, p, title=title or f"{robot.chain.title or robot.chain.name}: functional workspace")
        s.image(p, f"The functional workspace: {len(ws.positions):,} samples, near-singular ones in red "
                   f"({ws.threshold_rule}).", name=name)
    q0 = np.zeros(robot.n) if q_view is None else np.asarray(q_view, float)
    q0 = np.clip(q0, robot.chain.lower, robot.chain.upper)
    fig = robot_view(robot, q0, cloud=ws.positions, near_singular=ws.near_singular, path=path, targets=targets)
    s.view3d(fig, f"{name}_3d", "Interactive view: drag to turn, scroll to zoom, click a legend entry to hide it. "
                                "The robot is drawn by its DH frames (x red, y green, z blue)"
                                + ("; the slider moves it along the planned path." if path is not None else "."))
    s.results[name] = ws.to_dict()
    return ws


def planned_path(s: Study, robot: kin.Robot, windows, start, goal, *, planner: str = "RRTConnect",
                 time_limit: float = 2.0, seed: int = 0, objective: str = "none", key: str = "plan",
                 sigma_min: float | None = None):
    """Plan start → goal (SI) around ``windows`` (and above the σ_min floor ``sigma_min``, SI, when
    given), check it, and report it; returns the PlanResult."""
    from planning.ompl.planner import plan
    from planning.validate import check_path

    c = robot.chain
    for k, v in (("planner", planner), ("time limit (s)", time_limit), ("seed", seed), ("objective", objective)):
        s.input(f"{key}: {k}", v)
    if sigma_min is not None:
        s.input(f"{key}: σ_min floor (SI)", sigma_min)
    start, goal = np.asarray(start, float), np.asarray(goal, float)
    res = plan(robot, start, goal, windows, planner=planner, time_limit=time_limit, seed=seed, objective=objective,
               sigma_min=sigma_min)
    if res.success:
        # plan() returns its path proven; the report's figures are the dense re-check's (σ_min at every 0.1°)
        dense = check_path(robot, res.path, windows, sigma_min)
        res = dataclasses.replace(res, min_sigma=dense.min_sigma, check=dense)
    d = jsonable(res.to_dict())
    d["path"] = c.from_si(res.path).tolist() if res.success else []
    d["straight_line_length"] = float(np.linalg.norm(goal - start))
    s.results[key] = d
    if res.success:
        s.file(f"{key}.csv", path_csv(robot, res.path))
        s.table(["planner", "waypoints", "joint-space length", "straight line", "straight line valid",
                 "min σ_min", "windows"],
                [[res.planner, len(res.path), res.length, d["straight_line_length"], res.straight_line_valid,
                  res.min_sigma, "proven clear" if res.proven else "sampled"]],
                f"OMPL {res.planner} in {res.time_s:.3f} s (limit {time_limit} s, seed {seed}); the path is "
                f"re-checked independently of the planner; its waypoints are in `{key}.csv`.")
    else:
        reason = res.separation.reason if res.separation is not None else res.status
        s.text(f"**No path**: {reason}.")
    return res


def path_csv(robot: kin.Robot, path: np.ndarray) -> str:
    """A joint path as CSV text in the robot file's units (header q1…qn), as ``rmt plan --out`` writes it
    (:func:`studies.jointpath.path_csv_text`)."""
    return path_csv_text(robot, path)
