"""Learned-window trainings spread over worker processes give the reports of the same runs made one
after another (every run is seeded and single-threaded), in the order asked."""
from __future__ import annotations

import kin
from design.learned.ik import LearnedIK
from design.learned.runs import LearnedRuns, learned_runs
from design.learned.windows import jsonable_report, learned_windows
from kin.singular import analyse_singularities

RUNS = [(1500, 0), (1000, 1), (1500, 2)]


def _comparable(reports: list[dict]) -> list[dict]:
    """A report without its timings (the only entries that differ between two identical runs)."""
    out = []
    for r in reports:
        r = dict(r)
        r.pop("seconds", None)
        r["model"] = {k: v for k, v in r["model"].items() if k != "fit_seconds"}
        out.append(r)
    return out


def test_workers_give_the_serial_reports_in_order():
    robot = kin.load_robot("scara_rrp")
    analysis = analyse_singularities(robot)
    kw = dict(model=LearnedIK(hidden_layer_sizes=(12,), max_iter=40), n_eval=200)
    serial = [[jsonable_report(r) for r in learned_windows(robot, analysis=analysis, seed=s, n_train=n, **kw)[1]]
              for n, s in RUNS]
    told = []
    parallel = learned_runs(robot, analysis, RUNS, workers=2, progress=told.append, **kw)
    assert [_comparable(p) for p in parallel] == [_comparable(s) for s in serial]
    assert told == [f"training run: {n:,} poses, seed {s}" for n, s in RUNS]
    # different seeds really differ (the comparison above could not pass by all runs being alike)
    assert serial[0][0]["width"] != serial[2][0]["width"]
    one = learned_runs(robot, analysis, RUNS[:1], workers=1, **kw)
    assert _comparable(one[0]) == _comparable(serial[0])


def test_the_caller_works_while_the_runs_train():
    robot = kin.load_robot("scara_rrp")
    analysis = analyse_singularities(robot)
    kw = dict(model=LearnedIK(hidden_layer_sizes=(12,), max_iter=40), n_eval=200)
    with LearnedRuns(robot, analysis, RUNS[:2], workers=2, **kw) as pending:
        assert pending.workers == 2
        mine = learned_windows(robot, analysis=analysis, seed=5, n_train=1000, **kw)[1]
        theirs = pending.results()
    assert len(theirs) == 2 and mine[0]["status"] == "ok"
    assert _comparable(theirs[1]) == _comparable(
        [jsonable_report(r) for r in learned_windows(robot, analysis=analysis, seed=1, n_train=1000, **kw)[1]])
