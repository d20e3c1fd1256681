"""planning.certify.points: segments proven clear of point-set windows, checked against dense states
(every distance to every point computed in numpy, and ``window.contains``), on the Panda's and the
iiwa's windows of margin 0.05 rad and on a window of discs."""
import math

import numpy as np
import pytest

from planning.certify import certify_path
from planning.certify.points import SLACK, PointSetProver, certify_point_set, segment_clear
from planning.validate import check_path
from planning.windows import PointSetWindow
from tests.planning.seven_dof import ROBOTS, inside_numpy, margin_windows, through_window

DENSE = 10_001          # states per segment in the dense checks


def _dense(a, b, count=DENSE):
    t = np.linspace(0.0, 1.0, count)
    return t, a + t[:, None] * (b - a)


def _segments(robot, ws, w, rng, count):
    """Random segments of three kinds: between configurations outside the windows, aimed at a
    point of ``w`` (crossing or grazing it), and passing a point of ``w`` at about its width."""
    lo, hi = robot.chain.lower, robot.chain.upper
    cols = [j - 1 for j in w.joints]
    Q = robot.random_configurations(4 * count, seed=int(rng.integers(1 << 30)))
    Q = Q[~ws.contains(Q)]
    out = [(Q[i], Q[-1 - i]) for i in range(count)]
    for i in range(count):
        b = Q[count + i].copy()
        b[cols] = w.points[rng.integers(len(w.points))] + rng.normal(0.0, 0.04, len(cols))
        out.append((Q[i], np.clip(b, lo, hi)))
    for i in range(count):                                   # a chord at distance ≈ w from a point
        c = rng.uniform(lo, hi)
        c[cols] = w.points[rng.integers(len(w.points))]
        d = rng.normal(size=robot.n)
        d /= np.linalg.norm(d)
        off = rng.normal(size=robot.n)
        off[[j for j in range(robot.n) if j not in cols]] = 0.0
        off -= (off @ d) * d                                   # perpendicular to the motion
        nrm = np.linalg.norm(off[cols])
        if nrm < 1e-9:
            continue
        p = c + off * (w.width * rng.uniform(0.9, 1.1) / nrm)
        out.append((p - 0.3 * d, p + 0.3 * d))
    return out


@pytest.mark.parametrize("name", ROBOTS)
def test_proven_segments_are_clear_and_violations_are_inside(name):
    robot, ws = margin_windows(name)
    rng = np.random.default_rng(5)
    tally = {"proven": 0, "violation": 0, "unproven": 0}
    for w in [w for w in ws.windows if w.is_point_set]:
        for a, b in _segments(robot, ws, w, rng, 25):
            proof = certify_point_set(w, np.array([a, b]))
            t, Q = _dense(a, b)
            inside = w.contains(Q)
            assert np.array_equal(inside[::10], inside_numpy(w, Q[::10]))     # the window is its points' balls
            if proof.violation is None and not proof.unproven:
                tally["proven"] += 1
                assert not inside.any()
                assert segment_clear(w, a, b)
                continue
            assert not segment_clear(w, a, b)
            if proof.violation is None:
                tally["unproven"] += 1
                continue
            tally["violation"] += 1
            k, tv, depth = proof.violation
            q = a + tv * (b - a)
            assert k == 0 and w.contains(q) and inside_numpy(w, q[None])[0] and depth >= 0
            assert not inside[t < tv - 1e-6].any()                  # the entry: no dense state before it
    assert tally["proven"] >= 50 and tally["violation"] >= 30
    assert tally["unproven"] <= 2                                  # only grazes within the 1e-9 slack


@pytest.mark.parametrize("name", ROBOTS)
def test_segments_through_a_point_are_never_proven(name):
    robot, ws = margin_windows(name)
    rng = np.random.default_rng(9)
    for w in [w for w in ws.windows if w.is_point_set]:
        for _ in range(10):
            a, b = through_window(robot, w, rng)
            proof = certify_point_set(w, np.array([a, b]))
            assert proof.violation is not None and not segment_clear(w, a, b)
            assert w.contains(a + proof.violation[1] * (b - a))


def _line_past(w, n, gap, rng):
    """A segment 1 rad long whose closest approach to the window's first point is ``gap`` (over its
    joints), at the segment's middle, in a direction with no other point near."""
    cols = [j - 1 for j in w.joints]
    c = np.zeros(n)
    c[cols] = w.points[0]
    d = np.zeros(n)
    d[cols] = rng.normal(size=len(cols))
    d /= np.linalg.norm(d)
    off = np.zeros(n)
    off[cols] = rng.normal(size=len(cols))
    off -= (off @ d) * d
    off /= np.linalg.norm(off)
    p = c + gap * off
    return p - 0.5 * d, p + 0.5 * d


def test_a_graze_is_found_a_near_miss_proven_and_a_touch_left_open():
    """On the iiwa's (q2, q6) window (its points sit at q2 = q6 = 0): a segment passing 1e-4 inside
    the width is caught although 16 states along it all lie outside; one passing 1e-6 outside is
    proven; one passing within the slack is neither proven nor called a violation."""
    robot, ws = margin_windows("kuka_iiwa14")
    w = next(w for w in ws.windows if w.joints == (2, 6))
    assert np.abs(w.points).max() < 1e-6                           # the set is one point of (q2, q6)
    rng = np.random.default_rng(1)
    a, b = _line_past(w, robot.n, w.width - 1e-4, rng)
    _, coarse = _dense(a, b, 16)
    assert not inside_numpy(w, coarse).any()                        # a sampled check misses it
    proof = certify_point_set(w, np.array([a, b]))
    assert proof.violation is not None and w.contains(a + proof.violation[1] * (b - a))
    a, b = _line_past(w, robot.n, w.width + 1e-6, rng)
    assert certify_point_set(w, np.array([a, b])).violation is None
    assert not certify_point_set(w, np.array([a, b])).unproven and segment_clear(w, a, b)
    assert not inside_numpy(w, _dense(a, b, 100_001)[1]).any()
    a, b = _line_past(w, robot.n, w.width + 0.5 * SLACK, rng)
    proof = certify_point_set(w, np.array([a, b]))
    assert proof.violation is None and proof.unproven == [0] and not segment_clear(w, a, b)


@pytest.mark.parametrize("name", ROBOTS)
def test_check_path_and_certify_path_call_point_set_windows_proven(name):
    robot, ws = margin_windows(name)
    Q = robot.random_configurations(400, seed=3)
    P = Q[~ws.contains(Q)][:6]
    proof = certify_path(ws, P)
    point_sets = [w.name for w in ws.windows if w.is_point_set]
    assert all(proof.methods[n] == "distance" for n in point_sets)
    chk = check_path(robot, P, ws)
    dense_inside = np.concatenate([ws.contains(_dense(P[k], P[k + 1], 2001)[1]) for k in range(len(P) - 1)])
    if proof.proven:
        assert chk.valid and chk.windows_check == "proven" and not dense_inside.any()
    else:
        assert proof.violation is not None and not chk.valid and chk.windows_check == "proven"


def _disc_window(rng) -> PointSetWindow:
    """Discs on the surface z = 0.3·sin(2x)·cos(y) over joints (1, 2, 3) of a 3-joint robot: points on
    a grid, unit normals of the surface, each radius the spacing (neighbouring discs overlap)."""
    x, y = np.meshgrid(np.linspace(-1, 1, 15), np.linspace(-1, 1, 15))
    x, y = x.ravel() + rng.normal(0, 0.01, x.size), y.ravel() + rng.normal(0, 0.01, y.size)
    z = 0.3 * np.sin(2 * x) * np.cos(y)
    N = np.column_stack([-0.6 * np.cos(2 * x) * np.cos(y), 0.3 * np.sin(2 * x) * np.sin(y), np.ones_like(x)])
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    return PointSetWindow("other: discs", "other", "discs", (1, 2, 3), 0.05, "margin", 3,
                          points=np.column_stack([x, y, z]), normals=N, radius=np.full(x.size, 2 / 14))


def _disc_distance_all(w, Q):
    """Distance (N,) to the nearest of all the discs, the disc formula over every disc (numpy)."""
    D = Q[:, None, :] - w.points[None]
    h = np.einsum("nkd,kd->nk", D, w.normals)
    t = np.sqrt(np.maximum(np.einsum("nkd,nkd->nk", D, D) - h * h, 0.0))
    return np.sqrt(h * h + np.maximum(t - w.radius[None], 0.0) ** 2).min(axis=1)


def test_disc_windows_are_enclosed_never_proven_wrongly():
    rng = np.random.default_rng(2)
    w = _disc_window(rng)
    # the enclosure (ball of w + r and slab of w about each disc) holds every configuration inside
    Q = rng.uniform(-1.2, 1.2, (20000, 3))
    inside = w.contains(Q)
    assert inside.any()
    D = Q[inside][:, None, :] - w.points[None]
    ball = np.linalg.norm(D, axis=2) <= w.width + w.radius[None]
    slab = np.abs((D * w.normals[None]).sum(axis=2)) <= w.width
    assert (ball & slab).any(axis=1).all()
    segments = []
    for _ in range(200):                     # random segments
        a = rng.uniform(-1.2, 1.2, 3)
        segments.append((a, a + rng.normal(0, 0.4, 3)))
    for i in rng.integers(len(w.points), size=60):   # parallel to a disc, just inside or outside its slab
        n = w.normals[i]
        t = np.cross(n, rng.normal(size=3))
        t /= np.linalg.norm(t)
        p = w.points[i] + n * w.width * rng.uniform(0.6, 1.2)
        segments.append((p - 0.2 * t, p + 0.2 * t))
    tally = {"proven": 0, "violation": 0, "unproven": 0}
    for a, b in segments:
        proof = certify_point_set(w, np.array([a, b]))
        t, S = _dense(a, b, 2001)
        if proof.violation is None and not proof.unproven:
            tally["proven"] += 1
            assert _disc_distance_all(w, S).min() > w.width and not w.contains(S).any()
            assert segment_clear(w, a, b)
        elif proof.violation is not None:
            tally["violation"] += 1
            assert w.contains(a + proof.violation[1] * (b - a)) and not segment_clear(w, a, b)
        else:
            tally["unproven"] += 1
            assert not segment_clear(w, a, b)
    assert tally["proven"] >= 30 and tally["violation"] >= 30
    # beside a disc's rim — inside its ball and its slab, 0.0531 from the disc — not proven, no violation
    lone = PointSetWindow("other: one disc", "other", "disc", (1, 2, 3), 0.05, "margin", 3,
                          points=np.zeros((1, 3)), normals=np.array([[0.0, 0.0, 1.0]]), radius=np.array([0.5]))
    a, b = np.array([-1.0, 0.535, 0.04]), np.array([1.0, 0.535, 0.04])
    _, S = _dense(a, b)
    assert _disc_distance_all(lone, S).min() == pytest.approx(math.hypot(0.035, 0.04))
    assert not lone.contains(S).any()
    proof = certify_point_set(lone, np.array([a, b]))
    assert proof.violation is None and proof.unproven == [0] and not segment_clear(lone, a, b)


def test_empty_and_hostile_segments():
    empty = PointSetWindow("other: none", "other", "none", (1, 2), 0.05, "margin", 2, points=np.zeros((0, 2)))
    assert certify_point_set(empty, np.array([[0.0, 0.0], [1.0, 1.0]])).violation is None
    assert segment_clear(empty, np.zeros(2), np.ones(2))
    w = PointSetWindow("other: one", "other", "one", (1, 2), 0.05, "margin", 2, points=np.zeros((1, 2)))
    huge = np.array([[1e200, -1e200], [-1e200, 1e200]])
    proof = certify_point_set(w, huge)
    assert proof.violation is None and proof.unproven == [0]         # never proven: left open
    assert not segment_clear(w, huge[0], huge[1])
    # a path of many rows: each segment settled on its own, the first violation reported
    P = np.array([[1.0, 1.0], [1.0, -1.0], [-1.0, 0.02], [1.0, 0.02], [1.0, 1.0]])
    proof = certify_point_set(w, P, first_only=False)
    assert proof.violation[0] == 2 and proof.unproven == []
    assert PointSetProver(w).excess(np.array([0.0, 0.04])) == 0.0 and PointSetProver(w).excess(np.ones(2)) > 0
