"""Singular error windows (planning.windows) against independent values.

Interval bounds are recomputed here from the closed-form roots (sin q = 0 at kπ, d4·c3 − a3·s3 = 0 at
atan2(d4, a3) + kπ); predicate windows are probed by walking along the factor's normal until |g|
crosses ε; dexterity windows are checked with σ_min (``robot.sigma_min``) on fresh random samples
drawn with a seed the builder never uses (it uses 0, 1, 2, 3 and 99); membership is compared with a
plain per-configuration Python loop.  Analyses are cached per module.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import kin
from kin.singular import analyse_singularities
from planning.errors import WindowError
from planning.windows import WindowSet, build_windows, dexterity_margins, window_for_factor

PI = math.pi
FRESH_SEED = 20240607          # ≠ the seeds build_windows / dexterity_margins use internally

try:    # share test_singularity's per-module cache when both files run in one session (saves ≈ 10 s)
    from test_singularity import analysed
except ImportError:   # pragma: no cover - e.g. --import-mode=importlib
    _CACHE: dict[str, tuple] = {}

    def analysed(name: str):
        if name not in _CACHE:
            robot = kin.load_robot(name)
            _CACHE[name] = (robot, analyse_singularities(robot))
        return _CACHE[name]


def interval_windows(W):
    return [(k, w) for k, w in enumerate(W.windows) if w.is_interval]


def predicate_windows(W):
    return [(k, w) for k, w in enumerate(W.windows) if not w.is_interval]


# ---- just inside / just outside --------------------------------------------------------------------
@pytest.mark.parametrize("name", ["fanuc_m16ib20", "puma560", "ur5e", "scara_rrp", "planar_2r"])
def test_interval_window_boundary(name):
    robot, A = analysed(name)
    m = 0.05
    W = build_windows(robot, margin=m, analysis=A)
    lo, hi = robot.chain.lower, robot.chain.upper
    rng = np.random.default_rng(31)
    checked = 0
    for k, w in interval_windows(W):
        f = A.factors[k]
        j = w.joint
        for r in f.solutions["values"]:
            for side in (-1.0, 1.0):
                q_in, q_out = rng.uniform(lo, hi), rng.uniform(lo, hi)
                q_in[j] = r + side * m * (1 - 1e-6)
                q_out[j] = r + side * m * (1 + 1e-6)
                if not lo[j] <= q_out[j] <= hi[j]:
                    assert w.contains(np.clip(q_in, lo, hi))   # clipped side: still inside up to the limit
                    continue
                assert w.contains(q_in), (w.name, r, side)
                assert not w.contains(q_out), (w.name, r, side)
                assert W.membership(q_in)[0, k] and not W.membership(q_out)[0, k]
                assert w.distance_out(q_in)[0] <= 0 < w.distance_out(q_out)[0]
                checked += 1
    assert checked >= 2


def _crossing(g, q0, n, target, t_step, t_max):
    """Smallest t > 0 with |g(q0 + t·n)| = target (first bracket on a fine step, then Brent)."""
    h = lambda t: abs(float(g((q0 + t * n)[None])[0])) - target
    t0 = 0.0
    while t0 < t_max:
        t1 = t0 + t_step
        if h(t1) > 0:
            return brentq(h, t0, t1, xtol=1e-16, rtol=1e-15)
        t0 = t1
    return None


@pytest.mark.parametrize("name", ["fanuc_m16ib20", "puma560", "ur5e"])
def test_predicate_window_boundary(name):
    robot, A = analysed(name)
    W = build_windows(robot, margin=0.05, analysis=A)
    lo, hi = robot.chain.lower, robot.chain.upper
    preds = predicate_windows(W)
    assert preds, f"{name}: expected a multi-joint (shoulder) factor with a predicate window"
    checked = 0
    for k, w in preds:
        f = A.factors[k]
        assert w.expr == f.expr
        eps = w.epsilon
        assert eps > 0
        S = f.samples[:: max(1, len(f.samples) // 15)]
        G = f.gradient(S)
        for q0, grad in zip(S, G):
            n = grad / np.linalg.norm(grad)
            for side in (-1.0, 1.0):
                t_step = eps / np.linalg.norm(grad) / 50
                t_in = _crossing(f, q0, side * n, eps * (1 - 1e-6), t_step, 1.0)
                t_out = _crossing(f, q0, side * n, eps * (1 + 1e-6), t_step, 1.0)
                if t_in is None or t_out is None:
                    continue
                q_in, q_out = q0 + t_in * side * n, q0 + t_out * side * n
                if not (np.all((q_out >= lo) & (q_out <= hi)) and np.all((q_in >= lo) & (q_in <= hi))):
                    continue
                assert t_in < t_out
                assert w.contains(q_in), (w.name, q0, side)
                assert not w.contains(q_out), (w.name, q0, side)
                assert W.membership(q_in)[0, k] and not W.membership(q_out)[0, k]
                checked += 1
    assert checked >= 10


# ---- dexterity windows -------------------------------------------------------------------------------
_DEX: dict[tuple, object] = {}


def dex_windows(name: str, s: float):
    if (name, s) not in _DEX:
        robot, A = analysed(name)
        _DEX[(name, s)] = build_windows(robot, sigma_min=s, analysis=A)
    return _DEX[(name, s)]


@pytest.mark.parametrize("name, s", [("fanuc_m16ib20", 0.02), ("scara_rrp", 0.02), ("puma560", 0.02),
                                     ("ur5e", 0.01)])
def test_dexterity_windows_keep_sigma_min(name, s):
    """Outside every σ_min window, σ_min ≥ s — on 50k fresh samples the builder has never seen."""
    robot, _ = analysed(name)
    W = dex_windows(name, s)
    assert all(w.method == "sigma_min" and w.width > 0 for w in W.windows)
    Q = np.random.default_rng(FRESH_SEED).uniform(robot.chain.lower, robot.chain.upper, size=(50_000, robot.n))
    sig = robot.sigma_min(Q)
    inside = W.contains(Q)
    bad = (~inside) & (sig < s)
    assert not bad.any(), (f"{name}: {bad.sum()} of 50000 fresh configurations are outside every window with "
                           f"σ_min < {s} (lowest {sig[bad].min():.5f}); e.g. q = {Q[bad][0].tolist()}")
    # the windows are needed (σ_min < s does occur inside them) and not the whole joint space
    assert (inside & (sig < s)).any()
    assert inside.mean() <= 0.5


def test_dexterity_threshold_too_high_raises():
    robot, A = analysed("ur5e")
    with pytest.raises(WindowError, match="choose a smaller threshold"):
        build_windows(robot, sigma_min=0.05, analysis=A)
    with pytest.raises(WindowError, match="choose a smaller threshold"):
        dexterity_margins(robot, A, 0.05)
    # a smaller threshold is accepted for the same machine (σ_min → 0 at q5, q3 = ±2π, the limits,
    # must be covered by windows at those roots, not charged to the roots at ±π)
    W = dex_windows("ur5e", 0.01)
    assert all(0 < w.width < 0.5 for w in W.windows)


def test_dexterity_bad_arguments_raise():
    robot, A = analysed("scara_rrp")
    for bad in (0.0, -0.1, float("nan"), float("inf")):
        with pytest.raises(WindowError):
            dexterity_margins(robot, A, bad)
    with pytest.raises(WindowError):
        dexterity_margins(robot, A, 0.02, measure="condition")


# ---- margin windows ------------------------------------------------------------------------------------
def _expected_intervals(roots, m, lo, hi):
    """Clip r ± m to [lo, hi] and merge overlaps (written out here, independently of the product)."""
    ivs = sorted((max(r - m, lo), min(r + m, hi)) for r in roots)
    out = []
    for a, b in ivs:
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


def ivs(intervals, expected, atol=1e-12):
    """Interval lists equal in length and bounds (to atol)."""
    a, b = np.asarray(intervals, float).reshape(-1, 2), np.asarray(expected, float).reshape(-1, 2)
    return a.shape == b.shape and bool(np.allclose(a, b, rtol=0, atol=atol))


def _by_kind(A, W, kind):
    ks = [k for k, f in enumerate(A.factors) if f.kind == kind]
    assert len(ks) == 1
    return W.windows[ks[0]]


def test_fanuc_margin_windows():
    robot, A = analysed("fanuc_m16ib20")
    lo, hi = robot.chain.lower, robot.chain.upper
    elbow_roots = [math.atan2(0.74, 0.1) + k * PI for k in (-1, 0, 1)]     # d4·c3 − a3·s3 = 0
    W = build_windows(robot, margin=0.05, analysis=A)
    assert [w.width for w in W.windows] == [0.05] * 3
    assert ivs(_by_kind(A, W, "wrist").intervals, [(-0.05, 0.05)])
    assert ivs(_by_kind(A, W, "elbow").intervals, [(r - 0.05, r + 0.05) for r in elbow_roots], 1e-9)
    # predicate window: ε = w · G, G ≥ max‖∇g‖ over the whole joint box (not only the zero set) and
    # within 0.1 % of it; ∇g by central differences on a 401 × 401 grid of (q2, q3) over the limits
    shoulder = _by_kind(A, W, "shoulder")
    f = A.by_kind("shoulder")[0]
    g2, g3 = np.meshgrid(np.linspace(lo[1], hi[1], 401), np.linspace(lo[2], hi[2], 401))
    S = np.zeros((g2.size, robot.n))
    S[:, 1], S[:, 2], h = g2.ravel(), g3.ravel(), 1e-6
    fd = np.stack([(f(S + h * e) - f(S - h * e)) / (2 * h) for e in np.eye(robot.n)], axis=1)
    grid_max = np.linalg.norm(fd, axis=1).max()
    G = shoulder.epsilon / 0.05
    assert grid_max <= G <= grid_max * 1.002
    zero_set_max = np.linalg.norm(f.gradient(f.samples), axis=1).max()
    assert G > zero_set_max          # the zero-set samples under-estimate the box's maximum

    # per-factor margins, in analysis order: wider than the limits (clipped), overlapping (merged)
    per_kind = {"wrist": 3.0, "elbow": 1.6, "shoulder": 0.1}
    W2 = build_windows(robot, margin=[per_kind[f.kind] for f in A.factors], analysis=A)
    assert [w.width for w in W2.windows] == [per_kind[f.kind] for f in A.factors]
    assert ivs(_by_kind(A, W2, "wrist").intervals, [(-2.44, 2.44)])                    # clipped
    assert ivs(_by_kind(A, W2, "elbow").intervals, [(-2.97, 5.06)])                    # 2·1.6 > π: one
    assert ivs(_by_kind(A, W2, "elbow").intervals, _expected_intervals(elbow_roots, 1.6, lo[2], hi[2]))
    W3 = build_windows(robot, margin=[{"wrist": 0.1, "elbow": 1.5, "shoulder": 0.1}[f.kind] for f in A.factors],
                       analysis=A)
    assert ivs(_by_kind(A, W3, "elbow").intervals, _expected_intervals(elbow_roots, 1.5, lo[2], hi[2]), 1e-9)
    assert len(_by_kind(A, W3, "elbow").intervals) == 3                                 # 2·1.5 < π: three


def test_ur5e_margin_windows_clip_at_the_limits():
    robot, A = analysed("ur5e")
    W = build_windows(robot, margin=0.05, analysis=A)
    expected = [(-2 * PI, -2 * PI + 0.05), (-PI - 0.05, -PI + 0.05), (-0.05, 0.05), (PI - 0.05, PI + 0.05),
                (2 * PI - 0.05, 2 * PI)]
    for kind in ("wrist", "elbow"):
        w = _by_kind(A, W, kind)
        assert w.width == 0.05
        assert ivs(w.intervals, expected, 1e-9), kind


def test_planar_margin_windows_merge():
    robot, A = analysed("planar_2r")
    W = build_windows(robot, margin=2.0, analysis=A)          # roots −π, 0, π: r ± 2 all overlap
    assert ivs(W.windows[0].intervals, [(-PI, PI)], 1e-12)
    W = build_windows(robot, margin=1.0, analysis=A)
    assert ivs(W.windows[0].intervals, [(-PI, -PI + 1), (-1, 1), (PI - 1, PI)], 1e-12)


def test_margin_errors():
    robot, A = analysed("fanuc_m16ib20")
    k = len(A.factors)
    for wrong in ([0.05] * (k - 1), [0.05] * (k + 1), []):
        with pytest.raises(WindowError, match="margins"):
            build_windows(robot, margin=wrong, analysis=A)
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(WindowError):
            build_windows(robot, margin=bad, analysis=A)
    with pytest.raises(WindowError):
        build_windows(robot, analysis=A)                                     # no width source
    with pytest.raises(WindowError):
        build_windows(robot, margin=0.05, sigma_min=0.02, analysis=A)        # two width sources
    with pytest.raises(WindowError):
        window_for_factor(A.factors[0], -1.0, "margin", robot.chain.lower, robot.chain.upper)


# ---- save / load ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, how", [("fanuc_m16ib20", {"margin": 0.3}), ("ur5e", {"margin": 0.2}),
                                       ("puma560", {"sigma_min": 0.02})])
def test_save_load_round_trip(tmp_path, name, how):
    robot, A = analysed(name)
    W = dex_windows(name, how["sigma_min"]) if "sigma_min" in how else build_windows(robot, analysis=A, **how)
    path = W.save(tmp_path / "windows.json")
    json.loads(path.read_text())                                   # plain JSON
    W2 = WindowSet.load(path)
    assert (W2.robot, W2.n, len(W2.windows)) == (W.robot, W.n, len(W.windows))
    assert W2.to_dict() == W.to_dict()
    Q = np.random.default_rng(41).uniform(robot.chain.lower, robot.chain.upper, size=(10_000, robot.n))
    M, M2 = W.membership(Q), W2.membership(Q)
    assert M.any() and not M.all()
    assert np.array_equal(M, M2)
    assert np.array_equal(W.which(Q), W2.which(Q))


def test_load_malformed_files_raise_naming_the_file(tmp_path):
    robot, A = analysed("fanuc_m16ib20")
    good = build_windows(robot, margin=0.05, analysis=A).to_dict()
    pred = next(i for i, w in enumerate(good["windows"]) if "epsilon" in w)
    no_eps = json.loads(json.dumps(good))
    del no_eps["windows"][pred]["epsilon"]
    bad_joint = json.loads(json.dumps(good))
    bad_joint["windows"][0]["joints"] = [9]
    bad_interval = json.loads(json.dumps(good))
    bad_interval["windows"][0]["intervals"] = [[0.0]]
    cases = {
        "not_json.json": "{this is not json",
        "empty.json": "",
        "list.json": "[1, 2, 3]",
        "no_windows.json": json.dumps({"robot": "x", "n": 6}),
        "n_not_int.json": json.dumps({**good, "n": "six"}),
        "no_epsilon.json": json.dumps(no_eps),
        "bad_joint.json": json.dumps(bad_joint),
        "bad_interval.json": json.dumps(bad_interval),
    }
    for fname, text in cases.items():
        path = tmp_path / fname
        path.write_text(text)
        with pytest.raises(WindowError) as err:
            WindowSet.load(path)
        assert str(path) in str(err.value), (fname, str(err.value))
    missing = tmp_path / "missing.json"
    with pytest.raises(WindowError) as err:
        WindowSet.load(missing)
    assert str(missing) in str(err.value)


# ---- vectorised membership ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["fanuc_m16ib20", "ur5e", "stanford_arm"])
def test_membership_is_vectorised_and_matches_a_loop(name):
    robot, A = analysed(name)
    W = build_windows(robot, margin=0.3, analysis=A)
    assert [w.expr for w in W.windows] == [f.expr for f in A.factors]
    rng = np.random.default_rng(51)
    lo, hi = robot.chain.lower, robot.chain.upper
    parts = [rng.uniform(lo, hi, size=(600, robot.n))]
    # configurations on several zero sets at once (in more than one window)
    for f in A.factors:
        if len(f.samples):
            S = f.samples[rng.choice(len(f.samples), 100)]
            for g in A.factors:
                if g is not f and g.single_joint is not None and g.solutions["values"]:
                    S = S.copy()
                    S[::2, g.single_joint] = rng.choice(g.solutions["values"], size=len(S[::2]))
            parts.append(S)
    Q = np.concatenate(parts)
    N, k = len(Q), len(W.windows)

    M = W.membership(Q)
    assert M.shape == (N, k) and M.dtype == bool
    which, contains = W.which(Q), W.contains(Q)
    assert which.shape == (N,) and contains.shape == (N,)

    loop_M = np.zeros((N, k), bool)
    for i, q in enumerate(Q):
        for c, (w, f) in enumerate(zip(W.windows, A.factors)):
            if w.is_interval:
                loop_M[i, c] = any(a <= q[w.joints[0] - 1] <= b for a, b in w.intervals)
            else:
                loop_M[i, c] = abs(f(q)) <= w.epsilon
    loop_which = np.array([next((c for c in range(k) if loop_M[i, c]), -1) for i in range(N)])
    assert np.array_equal(M, loop_M)
    assert np.array_equal(which, loop_which)
    assert np.array_equal(contains, loop_M.any(axis=1))
    assert (loop_which == -1).any() and (loop_which >= 0).any()
    assert (loop_M.sum(axis=1) >= 2).any()                    # "first" is really exercised
    for c, w in enumerate(W.windows):
        assert np.array_equal(w.distance_out(Q) <= 0, loop_M[:, c])

    # one configuration: (1, k), (1,), and a plain bool
    q = Q[0]
    assert W.membership(q).shape == (1, k) and W.which(q).shape == (1,)
    assert isinstance(W.contains(q), bool) and W.contains(q) == bool(loop_M[0].any())
    assert isinstance(W.windows[0].contains(q), bool)


def test_another_robots_analysis_is_refused_with_a_typed_error():
    fanuc, _ = analysed("fanuc_m16ib20")
    _, puma_analysis = analysed("puma560")
    with pytest.raises(WindowError, match="analysis is of 'puma560'.*not of 'fanuc_m16ib20'"):
        build_windows(fanuc, margin=0.05, analysis=puma_analysis)
    scara, scara_analysis = analysed("scara_rrp")
    with pytest.raises(WindowError, match="analysis is of 'scara_rrp' \\(3 joints\\), not of 'fanuc_m16ib20'"):
        build_windows(fanuc, margin=0.05, analysis=scara_analysis)
    with pytest.raises(WindowError, match="analysis must be a SingularityAnalysis"):
        build_windows(fanuc, margin=0.05, analysis={"factors": []})


def test_windows_do_not_depend_on_the_analysis_seed_or_sample_count():
    robot, A = analysed("fanuc_m16ib20")
    ref = json.dumps(build_windows(robot, margin=0.05, analysis=A).to_dict())
    for seed, samples in ((3, 200), (10, 37)):
        other = analyse_singularities(robot, seed=seed, samples=samples)
        assert json.dumps(build_windows(robot, margin=0.05, analysis=other).to_dict()) == ref
    # dexterity margins are sampled: they come from the windows' own samples whatever analysis is passed
    d_ref = json.dumps(build_windows(robot, sigma_min=0.02, analysis=A).to_dict())
    other = analyse_singularities(robot, seed=3, samples=60)
    assert json.dumps(build_windows(robot, sigma_min=0.02, analysis=other).to_dict()) == d_ref


@pytest.mark.parametrize("kwargs, match", [
    ({"margin": "0.05"},
     r"margin \(rad for revolute, m for prismatic joints\) must be a finite number ≥ 0, got string"),
    ({"margin": True}, r"margin \(.*\) must be a finite number ≥ 0, got boolean"),
    ({"margin": 1 + 0j}, r"margin \(.*\) must be a finite number ≥ 0, got complex"),
    ({"margin": float("nan")}, r"margin \(.*\) = nan must be a finite number ≥ 0"),
    ({"margin": -0.1}, r"margin \(.*\) = -0.1 must be a finite number ≥ 0"),
    ({"sigma_min": "0.02"}, r"sigma_min \(SI\) must be a finite number > 0, got string"),
    ({"sigma_min": True}, r"sigma_min \(SI\) must be a finite number > 0, got boolean"),
    ({"sigma_min": 0.0}, r"sigma_min \(SI\) = 0.0 must be a finite number > 0"),
    ({"manipulability": float("inf")}, r"manipulability \(SI\) = inf must be a finite number > 0"),
])
def test_width_sources_are_checked(kwargs, match):
    robot, A = analysed("fanuc_m16ib20")
    with pytest.raises(WindowError, match=match):
        build_windows(robot, analysis=A, **kwargs)


def test_a_robot_name_is_not_a_robot_and_minus_zero_is_zero():
    with pytest.raises(WindowError, match="robot must be a kin.Robot.*got str"):
        build_windows("fanuc_m16ib20", margin=0.05)
    robot, A = analysed("fanuc_m16ib20")
    W = build_windows(robot, margin=-0.0, analysis=A)
    assert all(math.copysign(1.0, w.width) == 1.0 for w in W.windows)
