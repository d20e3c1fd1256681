"""The current placement is a candidate of every placement search and never loses to a worse one:
a ring of targets at the planar 2R's most dexterous radius (σ_min found in plain numpy) around the
current base — where the mean score is provably highest — and the ring whose centre alone reaches
every target, searched with too few candidates to find that centre."""
import numpy as np
import pytest

import kin
from design.place import PlacementRegion, place
from design.reach import ReachSettings, ScoreWeights
from design.task.model import Targets
from planning.cell import Cell

FAST = ReachSettings(starts=4, samples=1024, spins=4)
A1, A2 = 1.0, 0.8           # planar_2r.toml


@pytest.fixture(scope="module")
def r2():
    return kin.load_robot("planar_2r")


def _best_radius() -> float:
    """The reach at which σ_min of the 2R's 2×2 Jacobian is largest (it depends on q2 alone)."""
    q2 = np.linspace(1e-3, np.pi - 1e-3, 200_001)
    s1, c1, s12, c12 = 0.0, 1.0, np.sin(q2), np.cos(q2)
    J = np.empty((len(q2), 2, 2))
    J[:, 0, 0], J[:, 0, 1] = -A1 * s1 - A2 * s12, -A2 * s12
    J[:, 1, 0], J[:, 1, 1] = A1 * c1 + A2 * c12, A2 * c12
    q = q2[np.argmax(np.linalg.svd(J, compute_uv=False)[:, -1])]
    return float(np.sqrt(A1 ** 2 + A2 ** 2 + 2 * A1 * A2 * np.cos(q)))


def test_current_placement_at_the_optimum_is_reported(r2):
    # every target at the most dexterous reach from the current base: moving the base puts some target
    # at another reach, where σ_min is lower — the mean score is highest exactly here
    r = _best_radius()
    th = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    t = Targets(np.column_stack([r * np.cos(th), r * np.sin(th), 0 * th]), tolerance=1e-6)
    w = ScoreWeights(dexterity=1.0, clearance=0.0, limits=0.0, dexterity_ref=10.0)   # no cap at 1
    reg = PlacementRegion((-0.6, 0.6), (-0.6, 0.6), (0, 0), yaw=(0, 0))
    res = place(r2, t, region=reg, weights=w, settings=FAST, starts=2, candidates=16, grid=5, de_iterations=3)
    assert res.method == "current" and res.current_is_best
    assert np.allclose(res.u, 0.0)
    assert res.study.coverage == 1.0
    d = res.to_dict()
    assert d["current_is_best"] is True and d["method"] == "current"
    assert d["current"] == {"placement": [0.0] * 6, "candidate": True, "reason": None}
    assert any(n.startswith("the current placement is already the best found") for n in res.notes)
    for name, m in res.methods.items():
        assert m["value"] <= res.study.value + 1e-9 * max(1.0, res.study.value), name


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_never_worse_than_the_current_placement(r2, seed):
    # the dexterous ring around the cell's placement of the robot (not the origin), yaw free: every
    # search (IPOPT, differential evolution, the grid) must end at a value no lower than the current one's
    C = np.array([0.5, 0.3, 0.0])
    r = _best_radius()
    th = np.linspace(0, 2 * np.pi, 8, endpoint=False) + 0.1
    t = Targets(C + np.column_stack([r * np.cos(th), r * np.sin(th), 0 * th]), tolerance=1e-6)
    base = np.eye(4)
    base[:3, 3] = C
    w = ScoreWeights(dexterity=1.0, clearance=0.0, limits=0.0, dexterity_ref=10.0)
    reg = PlacementRegion((-0.5, 1.5), (-0.5, 1.5), (0, 0))
    res = place(r2, t, cell=Cell("empty", base=base), region=reg, weights=w, settings=FAST, starts=2, candidates=8,
                grid=4, de_iterations=3, seed=seed)
    assert res.before is not None and res.before.coverage == 1.0
    assert res.study.value >= res.before.value
    assert res.study.mean_score >= res.before.mean_score - 1e-9
    assert np.allclose(res.current, [*C, 0, 0, 0])
    for name, m in res.methods.items():
        assert m["value"] <= res.study.value + 1e-9 * res.study.value, name


def test_current_outside_the_region_is_said(r2):
    t = Targets(np.array([[1.0, 0.5, 0.0], [1.2, -0.3, 0.0]]), tolerance=1e-6)
    reg = PlacementRegion((0.5, 1.0), (-0.5, 0.5), (0, 0), yaw=(0, 0))
    res = place(r2, t, region=reg, settings=FAST, starts=1, candidates=4)
    assert res.method != "current" and res.current_reason is not None and "x 0" in res.current_reason
    assert any("the current placement is not a candidate" in n for n in res.notes)
    assert res.to_dict()["current"]["candidate"] is False
