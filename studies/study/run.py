"""The bundled study (``rmt study``, ``make run``): kinematics, the singular set, its windows, the
functional workspace and a planned joint path around the windows, for one machine.

A study file holds the robot, the configurations to evaluate (see :mod:`studies.study.kinematics`)
and optional sections, all in the robot file's units:

    [singularities]                      # factor det J and name the factors
    [windows]
    margin = 0.05                        # half-width: angle unit for revolute factors
    [workspace]
    samples = 200000
    seed = 0
    [plan]
    start = [...]                        # joint values
    goal = [...]
    planner = "RRTConnect"
    time_limit = 2.0
    seed = 0

:func:`run_study` computes everything and writes ``results.json`` (atomically) plus
``workspace.png`` and ``plan.csv`` into the output directory.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import kin

from studies.study import kinematics as ks
from studies.cli.common import factor_margins
from studies.study.kinematics import StudyFileError


def _field(section: dict, name: str, key: str, kind, default=None):
    if key not in section:
        if default is None:
            raise StudyFileError(f"{name}.{key}: missing")
        return default
    v = section[key]
    if kind is float and isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
        return float(v)
    if kind is int and isinstance(v, int) and not isinstance(v, bool):
        return v
    if kind is str and isinstance(v, str):
        return v
    if kind is list and isinstance(v, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
        return [float(x) for x in v]
    raise StudyFileError(f"{name}.{key}: {v!r} is not a valid {kind.__name__}")


def run_study(study: dict, out_dir: str | Path, progress=None) -> dict:
    """Run every section of a loaded study; returns the results dict (also written to out_dir)."""
    say = progress or (lambda text: None)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    say("kinematics")
    results = ks.run_kinematics_study(study)
    robot = kin.load_robot(study["robot"])
    c = robot.chain
    analysis = None
    if "singularities" in study or "windows" in study or "plan" in study:
        from kin.singular import analyse_singularities

        from studies.cli.singular import singularities_json
        say("singular set")
        analysis = analyse_singularities(robot)
        results["singularities"] = singularities_json(robot, analysis)
    windows = None
    if "windows" in study:
        from planning.windows import build_windows
        sec = study["windows"]
        margin = _field(sec, "windows", "margin", float)
        if margin < 0:
            raise StudyFileError(f"windows.margin: {margin} must be ≥ 0 (robot file units)")
        margins = factor_margins(c, analysis, margin)
        say("windows")
        windows = build_windows(robot, margin=margins, analysis=analysis)
        results["windows"] = windows.to_dict()
        Q = robot.random_configurations(200_000, seed=0)
        results["windows"]["share_of_joint_space"] = float(windows.contains(Q).mean())
    if "workspace" in study:
        from design.workspace import compute_workspace

        from studies.plots import plot_workspace
        sec = study["workspace"]
        say("workspace")
        ws = compute_workspace(robot, n_samples=_field(sec, "workspace", "samples", int, 100_000),
                               seed=_field(sec, "workspace", "seed", int, 0))
        results["workspace"] = ws.to_dict()
        png = plot_workspace(ws, out_dir / "workspace.png", title=f"{c.title or c.name}: functional workspace")
        results["workspace"]["plot"] = str(png)
    if "plan" in study:
        from planning.ompl.planner import plan

        from studies.cli.plan import write_path_csv
        sec = study["plan"]
        start = c.to_si(_field(sec, "plan", "start", list))
        goal = c.to_si(_field(sec, "plan", "goal", list))
        for what, q in (("start", start), ("goal", goal)):
            if len(q) != c.n:
                raise StudyFileError(f"plan.{what}: {len(q)} values; {c.name} has {c.n} joints")
        say("plan")
        res = plan(robot, start, goal, windows, planner=_field(sec, "plan", "planner", str, "RRTConnect"),
                   time_limit=_field(sec, "plan", "time_limit", float, 2.0), seed=_field(sec, "plan", "seed", int, 0))
        d = res.to_dict()
        d["path"] = c.from_si(res.path).tolist() if res.success else []
        d["straight_line_length"] = float(np.linalg.norm(goal - start))
        if res.success:
            d["csv"] = str(write_path_csv(robot, res.path, out_dir / "plan.csv"))
        results["plan"] = d
    ks.write_results(results, out_dir)
    return results
