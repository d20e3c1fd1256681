"""Gaussian-process refinement: expected improvement against its closed form; the coverage
threshold between levels; on a 2-parameter SCARA sweep the refined rows (marked with their
origin) hold a feasible design at least as good as the best of the initial grid, and the
reported improvement is the difference of the two bests read back from the database."""
import math

import numpy as np
import pytest
from scipy import integrate
from scipy.stats import norm

from design.sweep import LocalExecutor, load_sweep, read_sweep, run_sweep
from design.sweep.refine import coverage_threshold, expected_improvement
from tests.design.sweep.helpers import write_sweep


def test_expected_improvement_equals_the_integral():
    for mu, sd, best in [(0.3, 0.1, 0.35), (0.5, 0.2, 0.1), (0.0, 1.0, 0.0)]:
        direct, _ = integrate.quad(lambda v: max(best - v, 0.0) * norm.pdf(v, mu, sd), mu - 12 * sd, mu + 12 * sd,
                                   points=[best], limit=200)
        assert expected_improvement(np.array([mu]), np.array([sd]), best)[0] == pytest.approx(direct, rel=1e-7)


def test_coverage_threshold_between_levels():
    assert coverage_threshold(0.8, 9) == pytest.approx(7.5 / 9)      # 8/9 is the smallest feasible level
    assert coverage_threshold(1.0, 25) == pytest.approx(24.5 / 25)
    assert coverage_threshold(0.0, 10) < 0


def test_refinement_finds_a_design_at_least_as_good_as_the_grid(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, counts=(5, 5)))
    db = tmp_path / "r.sqlite"
    rep = run_sweep(sw, db, LocalExecutor(1), refine=4)
    meta, rows = read_sweep(db)
    grid = [r for r in rows if r["origin"] == "sample"]
    refined = [r for r in rows if r["origin"] == "refine"]
    assert len(grid) == 25 and len(refined) == 4 and all(r["status"] == "done" for r in rows)
    best_grid = min(r["metrics"]["objective"] for r in grid if r["metrics"]["feasible"])
    feas_ref = [r["metrics"]["objective"] for r in refined if r["metrics"]["feasible"]]
    assert feas_ref and min(feas_ref) <= best_grid
    assert rep.refine["best_before"] == best_grid
    assert rep.refine["improvement"] == pytest.approx(best_grid - min(feas_ref + [best_grid]), abs=1e-15)
    for r in refined:                                   # the structural length is the objective: a closed form
        assert r["metrics"]["objective"] == pytest.approx(r["params"]["A1"] + r["params"]["A2"] + 0.002, abs=1e-12)
        assert 0.1 <= r["params"]["A1"] <= 0.4 and 0.1 <= r["params"]["A2"] <= 0.4
    assert not math.isnan(rep.refine["best_after"])
