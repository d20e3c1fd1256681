"""design.learned.ik against independent values.

The SCARA's poses are recomputed here with a closed-form numpy forward kinematics written from the
DH table of kin/robots/scara_rrp.toml (read with ``tomllib``; standard DH, all α = 0, so
x = a1·c1 + (a2 + a3)·c12, y = a1·s1 + (a2 + a3)·s12, z = d1 + d2 + q3, R = Rz(q1 + q2)), checked
first against the reference values of docs/machines.md §2; the window's width is then recomputed from the
model's own predictions on those poses, never taken from the code's earlier output.  The PUMA's
shoulder evaluation poses are checked geometrically (the wrist centre on the cylinder of radius d2
about axis 1) with a plain numpy DH product of its TOML table.
"""
from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest

import kin
from design.learned.ik import LearnedIK, LearnedIKError, resolve_branch
from design.learned.windows import jsonable_report, learned_window, learned_windows
from kin.errors import RmtError
from kin.robotfile import ROBOT_DIR
from kin.singular import analyse_singularities
from planning.windows import WindowSet

MM = 1e-3
FRESH_SEED = 20240611          # a seed the module never uses internally for these draws


def robot_file(name: str) -> dict:
    with open(ROBOT_DIR / f"{name}.toml", "rb") as fh:
        return tomllib.load(fh)


SCARA = robot_file("scara_rrp")
J1, J2, J3 = SCARA["joints"]
A1, A2, A3 = J1["a"] * MM, J2["a"] * MM, J3["a"] * MM
D1, D2, D3 = J1["d"] * MM, J2["d"] * MM, J3["d"] * MM
LIM1, LIM2 = J1["limits"], J2["limits"]
LIM3 = [x * MM for x in J3["limits"]]


def scara_fk(Q: np.ndarray) -> np.ndarray:
    """Closed-form SCARA FK (N, 3) SI → (N, 4, 4); all α = 0 and θ3 = 0 in the table."""
    Q = np.atleast_2d(Q)
    q1, q2, q3 = Q.T
    c1, s1, c12, s12 = np.cos(q1), np.sin(q1), np.cos(q1 + q2), np.sin(q1 + q2)
    T = np.zeros((len(Q), 4, 4))
    T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c12, -s12, s12, c12
    T[:, 2, 2] = T[:, 3, 3] = 1.0
    T[:, 0, 3] = A1 * c1 + (A2 + A3) * c12
    T[:, 1, 3] = A1 * s1 + (A2 + A3) * s12
    T[:, 2, 3] = D1 + D2 + D3 + q3
    return T


def r2(Q: np.ndarray, P: np.ndarray) -> float:
    """Coefficient of determination averaged over the columns (plain numpy)."""
    ss_res = ((Q - P) ** 2).sum(axis=0)
    ss_tot = ((Q - Q.mean(axis=0)) ** 2).sum(axis=0)
    return float(np.mean(1.0 - ss_res / ss_tot))


@pytest.fixture(scope="module")
def scara():
    robot = kin.load_robot("scara_rrp")
    return robot, analyse_singularities(robot)


@pytest.fixture(scope="module")
def fitted(scara):
    """The default network (55 tanh units) on the default branch q2 ≥ 0; half the
    default training size to keep the module fast."""
    robot, analysis = scara
    return LearnedIK().fit(robot, n_samples=10_000, seed=0, analysis=analysis)


@pytest.fixture(scope="module")
def scara_window(scara, fitted):
    robot, analysis = scara
    (factor,) = analysis.factors
    return learned_window(robot, factor, model=fitted, seed=0, analysis=analysis)


def small_model() -> LearnedIK:
    return LearnedIK(max_iter=25)


# ---- the test's own FK -----------------------------------------------------------------------------
def test_numpy_scara_fk_matches_robots_md():
    T = scara_fk(np.array([[0.0, 0.0, -197 * MM], [0.5, 1.0, -150 * MM]]))
    assert T[0, :3, 3] / MM == pytest.approx([675.0, 0.0, -195.0], abs=1e-9)
    assert T[1, :3, 3] / MM == pytest.approx([229.29, 556.74, -148.0], abs=0.01)


# ---- the SCARA window --------------------------------------------------------------------------------
def test_scara_window_centred_on_q2_zero_with_recomputed_width(scara_window, fitted):
    window, report = scara_window
    assert report["status"] == "ok" and window.method == "learned"
    assert window.joints == (2,)
    (lo, hi), = window.intervals
    w = window.width
    assert lo == pytest.approx(-w, abs=1e-15) and hi == pytest.approx(w, abs=1e-15)     # centred on q2 = 0
    Q = report["data"]["q_true"]
    assert len(Q) == report["n_eval"] == 2000
    assert np.all(Q[:, 1] == 0.0)                                    # on the singular set
    assert np.all((Q[:, 0] >= LIM1[0]) & (Q[:, 0] <= LIM1[1]))
    assert np.all((Q[:, 2] >= LIM3[0] - 1e-12) & (Q[:, 2] <= LIM3[1] + 1e-12))
    assert np.ptp(Q[:, 0]) > 0.9 * (LIM1[1] - LIM1[0])               # the whole stretched-arm circle
    P = fitted.predict(scara_fk(Q))                                  # poses from the test's own FK
    width = float(np.abs(P[:, 1] - Q[:, 1]).max())
    assert w == pytest.approx(width, rel=1e-9, abs=1e-12)
    assert report["width"] == w
    assert report["singular_errors"]["max"][1] == pytest.approx(width, rel=1e-9, abs=1e-12)
    p95 = np.percentile(np.abs(P - Q), 95, axis=0)
    assert report["singular_errors"]["p95"] == pytest.approx(p95, rel=1e-9, abs=1e-12)


def test_scara_window_membership(scara_window):
    window, _ = scara_window
    w = window.width
    rng = np.random.default_rng(FRESH_SEED)
    Q = np.column_stack([rng.uniform(*LIM1, 500), np.zeros(500), rng.uniform(*LIM3, 500)])
    assert window.contains(Q).all()
    for q2, inside in ((1.01 * w, False), (-1.01 * w, False), (0.99 * w, True), (-0.99 * w, True)):
        Q[:, 1] = q2
        assert (window.contains(Q) == inside).all(), q2


def test_scara_report_is_the_method_alone(scara_window):
    # published values and the comparison with them belong to the studies (studies.published)
    window, report = scara_window
    assert not {"thesis", "published"} & set(report)
    assert report["width"] == window.width and report["intervals"] == [list(iv) for iv in window.intervals]
    assert report["seed"] == 0 and report["n_train"] == 10_000 and report["n_eval"] == 2000
    json.dumps(jsonable_report(report))                             # everything but "data" is JSON


def test_model_good_on_its_branch_and_not_better_at_the_singularity(fitted, scara_window, record_property):
    _, report = scara_window
    rng = np.random.default_rng(FRESH_SEED + 1)
    N = 4000
    Q = np.column_stack([rng.uniform(*LIM1, N), rng.uniform(0.0, LIM2[1], N), rng.uniform(*LIM3, N)])
    P = fitted.predict(scara_fk(Q))
    score = r2(Q, P)
    assert score > 0.9                                              # the fitted IK works on its branch
    assert report["heldout_r2"] == pytest.approx(score, abs=0.02)   # and the report says so
    # away from the singularity (and the joint limit) versus on it
    far = (Q[:, 1] > 0.3) & (Q[:, 1] < LIM2[1] - 0.3)
    err_far = np.abs(P[far, 1] - Q[far, 1]).mean()
    Qs = report["data"]["q_true"]
    err_sing = np.abs(fitted.predict(scara_fk(Qs))[:, 1]).mean()
    ratio = err_sing / err_far
    record_property("singular_to_regular_mean_q2_error_ratio", float(ratio))
    assert ratio >= 1.0


def test_fitted_model_predicts_single_and_batch(fitted):
    q = np.array([0.4, 1.2, -0.2])
    T = scara_fk(q)
    p1 = fitted.predict(T[0])
    assert p1.shape == (3,)
    assert np.array_equal(p1, fitted.predict(T)[0])
    assert fitted.features_ == ["x", "y", "z"]


# ---- reproducibility ---------------------------------------------------------------------------------
def test_same_seed_same_window_different_seed_different(scara):
    robot, analysis = scara
    (factor,) = analysis.factors
    proto = small_model()
    kw = dict(model=proto, n_train=4000, n_eval=500, analysis=analysis)
    wa, ra = learned_window(robot, factor, seed=3, **kw)
    wb, rb = learned_window(robot, factor, seed=3, **kw)
    wc, rc = learned_window(robot, factor, seed=4, **kw)
    assert not proto.is_fitted                                       # the prototype is cloned, not changed
    assert wa.to_dict() == wb.to_dict()
    assert np.array_equal(ra["data"]["q_true"], rb["data"]["q_true"])
    assert np.array_equal(ra["data"]["q_pred"], rb["data"]["q_pred"])
    assert wc.width != wa.width
    assert not np.array_equal(rc["data"]["q_true"], ra["data"]["q_true"])


def test_learned_windows_scara_reproducible(scara, fitted, tmp_path):
    robot, analysis = scara
    ws, reports = learned_windows(robot, analysis=analysis, seed=0, model=fitted)
    assert isinstance(ws, WindowSet) and len(ws.windows) == 1 and len(reports) == 1
    assert reports[0]["factor_index"] == 0 and reports[0]["status"] == "ok"
    ws2, _ = learned_windows(robot, analysis=analysis, seed=0, model=fitted)
    assert ws.to_dict() == ws2.to_dict()
    loaded = WindowSet.load(ws.save(tmp_path / "learned.json"))
    assert np.allclose(loaded.windows[0].intervals, ws.windows[0].intervals, rtol=0, atol=1e-15)
    assert loaded.windows[0].method == "learned"


# ---- branches ------------------------------------------------------------------------------------------
def test_scara_branches(scara):
    robot, analysis = scara
    default = resolve_branch(robot, None, analysis)
    assert default.spec == {2: 1}
    assert [default.lower[1], default.upper[1]] == pytest.approx([0.0, LIM2[1]])
    down = resolve_branch(robot, {2: -1}, analysis)
    assert [down.lower[1], down.upper[1]] == pytest.approx([LIM2[0], 0.0])
    assert [down.lower[0], down.upper[0]] == pytest.approx(LIM1)
    model = small_model().fit(robot, n_samples=2000, seed=1, branch={2: -1}, analysis=analysis)
    assert (model.sample_configurations(300, seed=2)[:, 1] <= 0).all()
    w, rep = learned_window(robot, analysis.factors[0], model=model, n_eval=200, seed=1)
    assert w.intervals[0][0] < 0 < w.intervals[0][1]
    assert rep["branch"]["ranges"]["q2"] == pytest.approx([LIM2[0], 0.0])


# ---- a multi-joint factor and a skipped one ------------------------------------------------------------
def test_puma_shoulder_window_uses_the_worst_of_its_joints():
    robot = kin.load_robot("puma560")
    analysis = analyse_singularities(robot)
    (shoulder,) = analysis.by_kind("shoulder")
    w, rep = learned_window(robot, shoulder, model=small_model(), n_train=3000, n_eval=300, seed=0,
                            analysis=analysis)
    Q, P = rep["data"]["q_true"], rep["data"]["q_pred"]
    assert w.epsilon is not None and w.epsilon > 0
    assert w.width == pytest.approx(np.abs(P - Q)[:, [1, 2]].max(), rel=1e-12)
    # independent: the wrist centre (origin of frame 4) lies on the cylinder of radius |d2| about axis 1
    rows = robot_file("puma560")["joints"]
    radii = []
    for q in Q[:50]:
        T = np.eye(4)
        for row, qi in zip(rows[:4], q[:4]):
            th, d, a, al = qi + math.radians(row["theta"]), row["d"] * MM, row["a"] * MM, math.radians(row["alpha"])
            ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
            T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                              [0, sa, ca, d], [0, 0, 0, 1]])
        radii.append(math.hypot(T[0, 3], T[1, 3]))
    assert radii == pytest.approx([rows[1]["d"] * MM] * len(radii), abs=1e-9)


def test_factor_outside_limits_is_skipped_and_said():
    robot = kin.load_robot("spherical_rrp")
    ws, reports = learned_windows(robot, seed=0, model=LearnedIK(max_iter=10), n_train=1000, n_eval=100)
    skipped = [r for r in reports if r["status"] == "skipped"]
    assert [r["factor"]["kind"] for r in skipped] == ["prismatic"]
    assert "outside the joint limits" in skipped[0]["reason"]
    assert len(ws.windows) == len(reports) - 1


# ---- bad parameters ------------------------------------------------------------------------------------
@pytest.mark.parametrize("kw, word", [
    ({"n_train": 0}, "n_train"), ({"n_train": -5}, "n_train"), ({"n_train": 2.5}, "n_train"),
    ({"n_eval": 0}, "n_eval"), ({"seed": -1}, "seed"),
    ({"branch": {7: 1}}, "branch"), ({"branch": {0: 1}}, "branch"), ({"branch": {"elbow": 1}}, "branch"),
    ({"branch": {2: 0}}, "sign"), ({"branch": {2: 2}}, "sign"), ({"branch": {2: True}}, "sign"),
    ({"branch": [2]}, "branch"),
])
def test_bad_parameters_name_the_parameter(scara, kw, word):
    robot, analysis = scara
    with pytest.raises(LearnedIKError, match=word) as info:
        learned_window(robot, analysis.factors[0], analysis=analysis, **kw)
    assert isinstance(info.value, RmtError) and isinstance(info.value, ValueError)
    if "branch" in kw and isinstance(kw["branch"], dict) and 7 in kw["branch"]:
        assert "1–3" in str(info.value)                                 # the allowed joints are listed


def test_bad_estimator_settings_and_inputs(scara, fitted):
    robot, analysis = scara
    with pytest.raises(LearnedIKError, match="n_samples"):
        LearnedIK().fit(robot, n_samples=0, analysis=analysis)
    with pytest.raises(LearnedIKError, match="activation"):
        LearnedIK(activation="sigmoid").fit(robot, n_samples=100, analysis=analysis)
    with pytest.raises(LearnedIKError, match="hidden_layer_sizes"):
        LearnedIK(hidden_layer_sizes=(0,)).fit(robot, n_samples=100, analysis=analysis)
    with pytest.raises(LearnedIKError, match="not fitted"):
        LearnedIK().predict(np.eye(4))
    bad = np.eye(4)
    bad[0, 3] = np.nan
    with pytest.raises(LearnedIKError, match="finite"):
        fitted.predict(bad)
    with pytest.raises(LearnedIKError, match="shape"):
        fitted.predict(np.zeros((3, 3)))
    with pytest.raises(LearnedIKError, match="n_train"):
        learned_window(robot, analysis.factors[0], model=fitted, n_train=100)
    with pytest.raises(LearnedIKError, match="branch"):
        learned_window(robot, analysis.factors[0], model=fitted, branch={2: -1}, analysis=analysis)


def test_ctrl_c_during_training_stops_instead_of_returning_a_half_trained_network(scara, monkeypatch):
    # scikit-learn's adam/sgd loop catches KeyboardInterrupt and only warns; fit must re-raise it
    from sklearn.neural_network import MLPRegressor

    def interrupt(self, *args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(MLPRegressor, "_update_no_improvement_count", interrupt)
    with pytest.raises(KeyboardInterrupt):
        robot, analysis = scara
        LearnedIK().fit(robot, n_samples=200, seed=0, analysis=analysis)
