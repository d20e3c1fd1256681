"""Running a study (``rmt study``, ``make run``): kinematics, the singular set, its windows, the
functional workspace and a planned joint path around the windows, for one machine.

The study file's format (every key, unit and default) is in the README ("Study files") and is
validated by :func:`studies.study.kinematics.load_study` before anything runs.

:func:`run_study` writes ``results.json``, ``workspace.png`` and ``plan.csv`` into a fresh hidden
directory beside ``out_dir`` and moves it into place only when the study has finished
(:func:`kin.output.fresh_directory`), so an interrupted or failed run never leaves new files beside
old results.  ``results.json`` is strict JSON: a value that is not finite is written as ``null``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

import kin
from kin.output import fresh_directory

from studies.cli.common import jsonable, require_task_rows
from studies.study import kinematics as ks

#: the files a run writes (an existing run directory holding anything else is not replaced)
RUN_FILES = ("results.json", "workspace.png", "plan.csv")


def run_study(study: dict, out_dir: str | Path, progress=None) -> dict:
    """Run every section of a loaded study (:func:`~studies.study.kinematics.load_study`); returns the
    results dict, also written to ``out_dir/results.json`` with the plots.  ``results["ok"]`` is
    False when the plan section found no path."""
    say = progress or (lambda text: None)
    out_dir = Path(out_dir)
    with fresh_directory(out_dir, RUN_FILES) as tmp:
        results = _run(study, out_dir, tmp, say)
        results = jsonable(results)
        ks.write_results(results, tmp)
    return results


def _run(study: dict, out_dir: Path, tmp: Path, say) -> dict:
    robot = require_task_rows(kin.load_robot(study["robot"]))
    say("kinematics")
    results = ks.run_kinematics_study(study)
    c = robot.chain
    results["ok"] = True
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

        from studies.cli.common import factor_margins
        margins = factor_margins(c, analysis, study["windows"]["margin"], "windows.margin")
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
        ws = compute_workspace(robot, n_samples=sec["samples"], seed=sec["seed"])
        results["workspace"] = ws.to_dict()
        plot_workspace(ws, tmp / "workspace.png", title=f"{c.title or c.name}: functional workspace")
        results["workspace"]["plot"] = str(out_dir / "workspace.png")
    if "plan" in study:
        from planning.ompl.planner import plan

        from studies.cli.plan import write_path_csv
        sec = study["plan"]
        start, goal = c.to_si(sec["start"]), c.to_si(sec["goal"])
        say("plan")
        res = plan(robot, start, goal, windows, planner=sec["planner"], time_limit=sec["time_limit"],
                   seed=sec["seed"], objective=sec["objective"])
        d = res.to_dict()
        d["path"] = c.from_si(res.path).tolist() if res.success else []
        d["straight_line_length"] = float(np.linalg.norm(goal - start))
        if res.success:
            write_path_csv(robot, res.path, tmp / "plan.csv")
            d["csv"] = str(out_dir / "plan.csv")
        else:
            results["ok"] = False
        results["plan"] = d
    return results
