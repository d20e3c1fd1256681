"""One window, one verdict: every command builds the same window whatever the seed, and every path
``rmt plan`` returns is accepted by ``rmt check-path`` and by an independent numpy check.

The independent check reads only the FANUC M-16iB/20's DH table (tests/dh_numpy.py): its shoulder
factor is the signed distance of the wrist centre from the axis of joint 1 (a1 + a2·cos q2 +
a3·cos(q2+q3) + d4·sin(q2+q3)), so |g| is the wrist centre's radial distance computed from a plain
DH product; the wrist and elbow roots are closed forms (q5 = 0; d4·c3 − a3·s3 = 0).
"""
from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest

import kin
from kin.compiled import cache_dir
from kin.singular import analyse_singularities
from planning.ompl import plan
from planning.validate import check_path
from planning.windows import build_windows
from studies.cli import main
from studies.cli.common import windows_from_args
from studies.jsonio import dump
from studies.study.windows import factor_margins
from tests.dh_numpy import dh_standard

ISSUE_START = ["2.4108", "0.4729", "2.6727", "-1.9392", "1.5042", "1.629"]
ISSUE_GOAL = ["1.892", "2.4863", "4.5218", "-1.6025", "1.4925", "4.7867"]
MARGIN = 0.05


def _cli(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def _cold_windows_cache():
    shutil.rmtree(cache_dir() / "windows", ignore_errors=True)


# ---- the same window from every entry point, for every seed -----------------------------------------
@pytest.mark.parametrize("name", ["fanuc_m16ib20", "ur5e", "abb_irb120", "cnc_rrrppp", "stanford_arm"])
def test_every_entry_point_builds_the_same_windows(name, capsys):
    robot = kin.load_robot(name)
    texts = {}
    for seed in (0, 3, 10):
        _cold_windows_cache()
        rc, out, _ = _cli(["windows", name, "--margin", str(MARGIN), "--seed", str(seed), "--json"], capsys)
        assert rc == 0
        texts[f"rmt windows --seed {seed} (built)"] = out.strip()
        rc, out, _ = _cli(["windows", name, "--margin", str(MARGIN), "--seed", str(seed), "--json"], capsys)
        texts[f"rmt windows --seed {seed} (cached)"] = out.strip()
        analysis = analyse_singularities(robot, seed=seed, samples=50 + seed)
        api = build_windows(robot, margin=factor_margins(robot.chain, analysis, MARGIN), analysis=analysis)
        texts[f"build_windows, analysis seed {seed}"] = dump(api.to_dict())
    # what rmt plan, check-path and validate-toolpath use
    texts["windows_from_args (cached)"] = dump(windows_from_args(robot, MARGIN, None).to_dict())
    _cold_windows_cache()
    texts["windows_from_args (built)"] = dump(windows_from_args(robot, MARGIN, None).to_dict())
    assert len(set(texts.values())) == 1, [k for k, v in texts.items() if v != texts["rmt windows --seed 0 (built)"]]
    d = json.loads(texts["windows_from_args (built)"])
    for w in d["windows"]:
        assert w["detail"]["proof"] in ("exact", "interval bound")
        assert ("epsilon" in w) == (w["detail"]["proof"] == "interval bound")


def test_windows_of_a_numeric_analysis_do_not_follow_the_seed(capsys):
    """The Panda's set is found numerically: its point-set windows come from the windows' own samples
    whatever --seed says, and say that they are sampled."""
    outs = []
    for seed in (0, 3):
        rc, out, _ = _cli(["windows", "franka_panda", "--margin", "0.05", "--seed", str(seed), "--exact-timeout", "1",
                           "--json"], capsys)
        assert rc == 0
        outs.append(out)
    assert outs[0] == outs[1]
    d = json.loads(outs[0])
    assert d["windows"] and all(w["type"] == "points" and w["detail"]["proof"] == "sampled"
                                for w in d["windows"])
    # each says how many fresh points of its set it misses (measured, not assumed)
    for w in d["windows"]:
        m = w["detail"]["miss"]
        assert m["fresh_set_points"] > 0 and 0 <= m["outside_window"] <= m["fresh_set_points"]
        assert m["miss_rate"] == pytest.approx(m["outside_window"] / m["fresh_set_points"])
        assert (m["outside_window"] > 0) == (m["largest_distance"] > w["width"])


PANDA_THROUGH = """q1,q2,q3,q4,q5,q6,q7
-1.502480420981592069,-0.06943993719121679953,-1.606061048800166091,-1.310360171321739209,-1.928642496754534363,1.395724077301940591,2.040144920656581817
-1.532058326214370325,0.06943993719131730247,-1.498018659474466219,-1.601324110132232192,-2.131372778977080884,1.376967408642998825,1.994835137110473333
"""


def test_sampled_windows_are_said_and_a_sigma_floor_catches_what_they_miss(capsys, tmp_path):
    """A Panda path through an exact singularity (σ_min ≈ 1e-14 between its rows, found by a tester)
    that the sampled windows miss: check-path proves the path clear of the windows as they are, says
    that they are sampled and how much of the singular set they miss, and --sigma-floor proves the
    path invalid."""
    path = tmp_path / "through.csv"
    path.write_text(PANDA_THROUGH)
    robot = kin.load_robot("franka_panda")
    P = np.loadtxt(path, delimiter=",", skiprows=1)
    t = np.linspace(0, 1, 2001)[:, None]
    assert robot.sigma_min(P[0] + t * (P[1] - P[0])).min() < 1e-6          # it does pass a singularity
    # without options the robot's default σ_min floor (10⁻³ SI) proves the path invalid (issue 29, finding 3)
    rc, out, err = _cli(["check-path", "franka_panda", str(path), "--margin", "0.05"], capsys)
    assert rc == 1 and "INVALID" in out and "sigma_min" in out and "default floor of franka_panda, 0.001 (SI)" in out
    rc, out, err = _cli(["check-path", "franka_panda", str(path), "--margin", "0.05", "--no-singularity-check"],
                        capsys)
    assert rc == 0 and "windows of ±0.05 rad (--margin 0.05, robot file unit rad) proven" in out
    assert "are sampled" in err and "fresh points of the singular set" in err
    rc, out, err = _cli(["check-path", "franka_panda", str(path), "--margin", "0.05", "--sigma-floor", "0.01"],
                        capsys)
    assert rc == 1 and "INVALID" in out and "sigma_min" in out


# ---- every returned path is accepted, for every seed ------------------------------------------------
def test_the_issue_query_is_accepted_by_check_path_for_seeds_0_to_19(capsys, tmp_path):
    for seed in range(20):
        path = tmp_path / f"path{seed}.csv"
        rc, out, err = _cli(["plan", "fanuc_m16ib20", "--start", *ISSUE_START, "--goal", *ISSUE_GOAL,
                             "--margin", "0.05", "--time-limit", "2", "--seed", str(seed), "--out", str(path),
                             "--json"], capsys)
        d = json.loads(out)
        assert rc == 0 and d["success"] and d["proven"], (seed, err)
        rc, out, err = _cli(["check-path", "fanuc_m16ib20", str(path), "--margin", "0.05", "--json"], capsys)
        c = json.loads(out)
        assert rc == 0 and c["valid"] and c["windows_check"] == "proven", (seed, out)


def _fanuc_dh(robot):
    c = robot.chain
    return [(float(c.resolve(j.a)), float(c.resolve(j.alpha)), float(c.resolve(j.d)), float(c.resolve(j.theta)))
            for j in c.joints]


def _wrist_centre_radius(dh, Q: np.ndarray) -> np.ndarray:
    """Distance of the wrist centre (origin of frame 4) from the axis of joint 1, by a plain DH product."""
    out = np.empty(len(Q))
    for i, q in enumerate(Q):
        T = np.eye(4)
        for k in range(4):
            a, alpha, d, theta = dh[k]
            T = T @ dh_standard(q[k] + theta, d, a, alpha)
        out[i] = math.hypot(T[0, 3], T[1, 3])
    return out


def _dense(P: np.ndarray, step: float) -> np.ndarray:
    rows = [P[:1]]
    for a, b in zip(P[:-1], P[1:]):
        k = max(1, int(np.ceil(np.abs(b - a).max() / step)))
        rows.append(a + np.linspace(0, 1, k + 1)[1:, None] * (b - a))
    return np.concatenate(rows)


def _queries(robot, windows, count: int):
    """Start/goal pairs outside every window, q5 within 0.3 rad of the wrist window, whose straight line
    enters the shoulder window (the planner must go round it), start and goal not separated."""
    from planning.certify import free_cells
    rng = np.random.default_rng(20261124)
    lo, hi = robot.chain.lower, robot.chain.upper
    cells = free_cells(lo, hi, windows)
    out = []
    while len(out) < count:
        a, b = rng.uniform(lo, hi), rng.uniform(lo, hi)
        side = rng.choice([-1.0, 1.0])
        a[4], b[4] = side * rng.uniform(0.06, 0.3), side * rng.uniform(0.06, 0.3)
        if windows.contains(a) or windows.contains(b):
            continue
        line = _dense(np.stack([a, b]), 0.01)
        shoulder = [k for k, w in enumerate(windows.windows) if w.kind == "shoulder"][0]
        if not windows.membership(line)[:, shoulder].any():
            continue
        if cells.separation(a, b) is not None:
            continue
        out.append((a, b))
    return out


def test_planned_paths_pass_check_path_and_an_independent_numpy_check():
    robot = kin.load_robot("fanuc_m16ib20")
    windows = windows_from_args(robot, MARGIN, None)
    eps = next(w.epsilon for w in windows.windows if w.kind == "shoulder")
    elbow_roots = np.array([math.atan2(0.74, 0.1) + k * math.pi for k in (-1, 0, 1)])
    dh = _fanuc_dh(robot)
    for seed, (a, b) in enumerate(_queries(robot, windows, 20)):
        res = plan(robot, a, b, windows, time_limit=5.0, seed=seed)
        assert res.success and res.proven, (seed, res.status)
        P = np.asarray(res.path)
        chk = check_path(robot, P, windows)
        assert chk.valid and chk.windows_check == "proven", (seed, chk)
        D = _dense(P, 2e-3)
        assert np.all(_wrist_centre_radius(dh, D) > eps), seed                       # shoulder
        assert np.all(np.abs(D[:, 4]) > MARGIN), seed                                # wrist, q5 = 0
        assert np.all(np.abs(D[:, 2][:, None] - elbow_roots[None, :]) > MARGIN), seed  # elbow


@pytest.mark.parametrize("planner", ["PRM*", "BIT*", "KPIECE1"])
def test_other_planners_paths_pass_check_path(planner):
    """Whatever the planner: a path it returns is accepted by check_path and the numpy check."""
    robot = kin.load_robot("fanuc_m16ib20")
    windows = windows_from_args(robot, MARGIN, None)
    eps = next(w.epsilon for w in windows.windows if w.kind == "shoulder")
    dh = _fanuc_dh(robot)
    returned = 0
    for seed, (a, b) in enumerate(_queries(robot, windows, 3)):
        res = plan(robot, a, b, windows, planner=planner, time_limit=2.0, seed=seed)
        if not res.success:          # an optimising planner may not finish in time; it then returns no path
            assert len(res.path) == 0
            continue
        returned += 1
        chk = check_path(robot, np.asarray(res.path), windows)
        assert res.proven and chk.valid and chk.windows_check == "proven", (planner, seed, chk)
        assert np.all(_wrist_centre_radius(dh, _dense(np.asarray(res.path), 2e-3)) > eps)
    assert returned >= 1


def test_the_shoulder_window_holds_the_margin_neighbourhood_of_its_zero_set():
    """The documented promise: every configuration within the width (joint distance) of the zero set
    is inside.  Zeros of the wrist-centre radius are found by bisection on q3 for given q2; points at
    distance ≤ w in random directions around them must be in the window."""
    robot = kin.load_robot("fanuc_m16ib20")
    windows = windows_from_args(robot, MARGIN, None)
    shoulder = next(w for w in windows.windows if w.kind == "shoulder")
    dh = _fanuc_dh(robot)
    lo, hi = robot.chain.lower, robot.chain.upper
    rng = np.random.default_rng(7)

    def signed(q2, q3):
        a1, a2, a3, d4 = dh[0][0], dh[1][0], dh[2][0], dh[3][2]
        return a1 + a2 * math.cos(q2) + a3 * math.cos(q2 + q3) + d4 * math.sin(q2 + q3)

    zeros = []
    for q2 in np.linspace(lo[1], hi[1], 60):
        grid = np.linspace(lo[2], hi[2], 400)
        vals = [signed(q2, x) for x in grid]
        for x0, x1, v0, v1 in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
            if v0 * v1 < 0:
                for _ in range(60):
                    xm = 0.5 * (x0 + x1)
                    if signed(q2, x0) * signed(q2, xm) <= 0:
                        x1 = xm
                    else:
                        x0 = xm
                zeros.append((q2, 0.5 * (x0 + x1)))
    assert len(zeros) > 40
    Q = []
    for q2, q3 in zeros:
        for _ in range(50):
            d = rng.normal(size=2)
            r = MARGIN * rng.uniform(0.5, 1.0) ** 0.5
            q = rng.uniform(lo, hi)
            q[1], q[2] = q2 + r * d[0] / np.linalg.norm(d), q3 + r * d[1] / np.linalg.norm(d)
            if lo[1] <= q[1] <= hi[1] and lo[2] <= q[2] <= hi[2]:
                Q.append(q)
    Q = np.array(Q)
    assert shoulder.contains(Q).all()
    # and the radius agrees with the window's factor (the same function, from the DH table alone)
    assert np.allclose(np.abs(shoulder.g(Q[:200])), _wrist_centre_radius(dh, Q[:200]), atol=1e-12)
