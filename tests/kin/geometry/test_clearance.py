"""kin.geometry.ClearanceModel: the compiled kernel against a plain numpy re-implementation written
here (frames from tests/dh_numpy.py, segment distances from their candidate points, the signed
distance of boxes and cylinders minimised by dense sampling and golden-section search), against the
numpy fallback (kin/geometry/clearance_numpy.py) and against itself (modes, threads, cap); sphere sets
against brute force; ignore sets, self pairs, invalid arguments.  Coal comparisons are in
test_clearance_coal.py.

The promise under test: a reported clearance never exceeds the true signed distance (beyond 1e-12 m of
rounding) and lies within 1e-6 m of it."""
from __future__ import annotations

import math
import os
import warnings
from unittest import mock

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kin
from kin.chain import Chain, Joint
from kin.errors import ArgumentError, ConfigurationError, GeometryError, RmtError
from kin.geometry import ClearanceModel, Contact, LinkCapsule, Obstacle, RobotGeometry, Shape, body_frames
from kin.geometry import clearance as clearance_module
from kin.geometry.clearance import sphere_tree
from kin.native import find_compiler
from tests.chain_factory import random_chain
from tests.dh_numpy import frames_numpy

ROBOTS = ("franka_panda", "fanuc_lrmate200id")
ABOVE = 1e-12       # m: how far a reported value may exceed the reference (rounding)
BELOW = 1e-6        # m: how far it may lie below it
needs_compiler = pytest.mark.skipif(find_compiler() is None, reason="no C compiler: the kernel is the numpy fallback")


# ---- a plain numpy reference -------------------------------------------------------------------------
def ref_frames(chain, Q, base=None) -> np.ndarray:
    """(N, n + 2, 4, 4) body poses from tests/dh_numpy.py (independent of kin.geometry.frames)."""
    W = np.eye(4) if base is None else np.asarray(base, float)
    out = []
    for q in np.atleast_2d(Q):
        fr = frames_numpy(chain, q)
        out.append([W @ T for T in fr] + [W @ fr[-1] @ chain.tool.matrix])
    return np.array(out)


def ref_capsules(chain, geometry, Q, base=None):
    """World segments (N, C, 3) a, b and radii (C,) and bodies (C,) of the geometry's capsules."""
    F = ref_frames(chain, Q, base)
    caps = geometry.capsules
    body = np.array([c.body for c in caps])
    Fb = F[:, body]
    A = np.einsum("ncij,cj->nci", Fb[:, :, :3, :3], np.array([c.a for c in caps])) + Fb[:, :, :3, 3]
    B = np.einsum("ncij,cj->nci", Fb[:, :, :3, :3], np.array([c.b for c in caps])) + Fb[:, :, :3, 3]
    return A, B, np.array([c.radius for c in caps]), body


def point_segment(p, a, b) -> np.ndarray:
    """Distance of points p from segments a–b (..., 3): the clamped projection."""
    d = b - a
    dd = np.einsum("...i,...i", d, d)
    t = np.clip(np.einsum("...i,...i", p - a, d) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    return np.linalg.norm(p - a - t[..., None] * d, axis=-1)


def segment_segment(a1, b1, a2, b2) -> np.ndarray:
    """Distance of segments (..., 3): the least of the four end points against the other segment and,
    where the lines' common perpendicular meets both segments inside, its length."""
    cands = [point_segment(a1, a2, b2), point_segment(b1, a2, b2), point_segment(a2, a1, b1), point_segment(b2, a1, b1)]
    d1, d2, r = b1 - a1, b2 - a2, a1 - a2
    a, e, b = (np.einsum("...i,...i", x, y) for x, y in ((d1, d1), (d2, d2), (d1, d2)))
    c, f = np.einsum("...i,...i", d1, r), np.einsum("...i,...i", d2, r)
    den = a * e - b * b
    ok = den > 1e-12 * np.maximum(a * e, 1e-300)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (b * f - c * e) / den
        t = (a * f - b * c) / den
    inside = ok & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)
    w = r + np.nan_to_num(s)[..., None] * d1 - np.nan_to_num(t)[..., None] * d2
    cands.append(np.where(inside, np.linalg.norm(w, axis=-1), np.inf))
    return np.min(cands, axis=0)


def sdf_box(p, h) -> np.ndarray:
    q = np.abs(p) - h
    return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)


def sdf_cylinder(p, radius, half) -> np.ndarray:
    q = np.stack([np.hypot(p[..., 0], p[..., 1]) - radius, np.abs(p[..., 2]) - half], axis=-1)
    return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)


def min_along(f, a, b, samples: int = 201, steps: int = 80) -> np.ndarray:
    """min over t in [0, 1] of the convex f(a + t (b − a)) (a, b: (M, 3)): the best of dense samples, then
    golden-section search between its neighbours (a value of f: an upper bound, ~1e-12 above the min)."""
    t = np.linspace(0.0, 1.0, samples)
    v = f(a[:, None] + t[None, :, None] * (b - a)[:, None])
    k = np.argmin(v, axis=1)
    lo, hi = t[np.maximum(k - 1, 0)], t[np.minimum(k + 1, samples - 1)]
    g = (math.sqrt(5) - 1) / 2
    at = lambda u: f(a + u[:, None] * (b - a))
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = at(x1), at(x2)
    for _ in range(steps):
        left = f1 < f2
        hi, lo = np.where(left, x2, hi), np.where(left, lo, x1)
        x2n, x1n = np.where(left, x1, lo + g * (hi - lo)), np.where(left, hi - g * (hi - lo), x2)
        f2n, f1n = np.where(left, f1, np.nan), np.where(left, np.nan, f2)
        x1, x2 = x1n, x2n
        f1 = np.where(np.isnan(f1n), at(x1), f1n)
        f2 = np.where(np.isnan(f2n), at(x2), f2n)
    return np.minimum(np.minimum(v.min(axis=1), f1), f2)


def ref_pair(a, b, r, shape: Shape) -> np.ndarray:
    """Signed clearance of capsules a–b (M, 3) of radii r (M,) against one primitive (the definition)."""
    T = shape.pose
    size = shape.size
    if shape.kind == "sphere":
        return point_segment(T[:3, 3], a, b) - r - size[0]
    if shape.kind == "capsule":
        e0, e1 = T[:3, 3] - size[1] * T[:3, 2], T[:3, 3] + size[1] * T[:3, 2]
        return segment_segment(a, b, np.broadcast_to(e0, a.shape), np.broadcast_to(e1, a.shape)) - r - size[0]
    local = lambda p: (p - T[:3, 3]) @ T[:3, :3]
    if shape.kind == "box":
        f = lambda p: sdf_box(local(p), np.array(size))
    else:
        f = lambda p: sdf_cylinder(local(p), size[0], size[1])
    return min_along(f, a, b) - r


def ref_clearance(chain, geometry, obstacles, Q, base=None, pairs=(), cap=np.inf) -> tuple[np.ndarray, np.ndarray]:
    """(clearance (N,), per-body obstacle minima (N, B)) by the reference, self pairs included."""
    A, B_, r, body = ref_capsules(chain, geometry, Q, base)
    N, nb = len(A), chain.n + 2
    per = np.full((N, nb), np.inf)
    for ob in obstacles:
        for c in range(len(r)):
            if body[c] in ob.ignore:
                continue
            v = np.full(N, np.inf)
            for sh in ob.shapes:
                v = np.minimum(v, ref_pair(A[:, c], B_[:, c], np.full(N, r[c]), sh))
            if ob.spheres is not None:
                S = ob.spheres
                for i in range(N):
                    v[i] = min(v[i], float((point_segment(S[:, :3], A[i, c], B_[i, c]) - r[c] - S[:, 3]).min()))
            per[:, body[c]] = np.minimum(per[:, body[c]], v)
    best = per.min(axis=1)
    for i, j in pairs:
        for ci in np.flatnonzero(body == i):
            for cj in np.flatnonzero(body == j):
                v = segment_segment(A[:, ci], B_[:, ci], A[:, cj], B_[:, cj]) - r[ci] - r[cj]
                best = np.minimum(best, v)
    return np.minimum(best, cap), np.minimum(per, cap)


# ---- cells ---------------------------------------------------------------------------------------------
def pose(rng, centre, spread=0.0) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
    T[:3, 3] = np.asarray(centre) + rng.uniform(-spread, spread, 3)
    return T


def random_cell(seed: int, n_obstacles: int = 10, spheres: int = 0) -> list[Obstacle]:
    """Obstacles around a robot at the origin: a table under it (ignoring the base and body 1, which
    stand on it), then random rotated (centres 0.35 m or more from the robot's axis)
    boxes, cylinders, spheres and capsules within reach, and optionally a sphere set."""
    rng = np.random.default_rng(seed)
    table = np.eye(4)
    table[:3, 3] = (0.0, 0.0, -0.03)
    cell = [Obstacle("table", (Shape("box", (0.9, 0.9, 0.02), table),), ignore={0, 1})]
    kinds = ["box", "cylinder", "sphere", "capsule"]
    for i in range(n_obstacles - 1):
        kind = kinds[i % 4]
        c = rng.uniform((-0.7, -0.7, 0.0), (0.7, 0.7, 1.1))
        while np.hypot(c[0], c[1]) < 0.35:               # not through the robot's column
            c = rng.uniform((-0.7, -0.7, 0.0), (0.7, 0.7, 1.1))
        if kind == "box":
            size = tuple(rng.uniform(0.02, 0.25, 3))
        elif kind == "sphere":
            size = (float(rng.uniform(0.03, 0.15)), 0.0, 0.0)
        else:
            size = (float(rng.uniform(0.02, 0.1)), float(rng.uniform(0.05, 0.3)), 0.0)
        cell.append(Obstacle(f"{kind} {i}", (Shape(kind, size, pose(rng, c)),)))
    if spheres:
        S = np.column_stack([rng.uniform((-0.2, 0.3, 0.2), (0.2, 0.7, 0.6), (spheres, 3)),
                             rng.uniform(0.002, 0.02, spheres)])
        cell.append(Obstacle("cloud", spheres=S))
    return cell


def model(robot_or_chain, obstacles=(), **kw) -> ClearanceModel:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return ClearanceModel(robot_or_chain, obstacles=obstacles, **kw)


@pytest.fixture
def numpy_backend(monkeypatch):
    """ClearanceModels built inside use the numpy fallback (RMTKIT_CC=none), and warn anew."""
    monkeypatch.setenv("RMTKIT_CC", "none")
    monkeypatch.delitem(clearance_module._loaded, "none", raising=False)


def fallback(robot_or_chain, obstacles=(), **kw) -> ClearanceModel:
    """The same model on the numpy fallback (built with RMTKIT_CC=none)."""
    with mock.patch.dict(os.environ, {"RMTKIT_CC": "none"}):
        m = model(robot_or_chain, obstacles, **kw)
    assert m.backend == "numpy"
    return m


@pytest.fixture(scope="module", params=ROBOTS)
def robot(request):
    return kin.load_robot(request.param)


# ---- whole robots ---------------------------------------------------------------------------------------
def test_whole_robots_match_the_reference_and_the_numpy_fallback(robot):
    cell = random_cell(1)
    Q = robot.random_configurations(2000, seed=3)
    m = model(robot, cell, self_pairs=(), cap=np.inf)
    d = m.clearance(Q)
    dn = fallback(robot, cell, self_pairs=(), cap=np.inf).clearance(Q)
    assert np.all(d <= dn + ABOVE + 2e-7) and np.all(np.abs(d - dn) <= 2e-7)      # both within TOL of the truth
    ref, per_ref = ref_clearance(robot.chain, robot.geometry, cell, Q[:300])
    assert np.all(d[:300] <= ref + ABOVE), float((d[:300] - ref).max())
    assert np.all(d[:300] >= ref - BELOW), float((ref - d[:300]).max())
    assert (d < 0).any() and (d > 0).any()                                        # both kinds of configuration
    ob, _ = m.per_body(Q[:300])
    assert np.all(ob <= per_ref + ABOVE) and np.all(ob >= per_ref - BELOW)


def test_modes_agree(robot):
    cell = random_cell(2, spheres=500)
    Q = robot.random_configurations(3000, seed=4)
    m = model(robot, cell, cap=0.3)
    d = m.clearance(Q)
    c = m.nearest(Q)
    ob, sf = m.per_body(Q)
    assert isinstance(c, Contact)
    assert np.array_equal(c.clearance, d)
    assert np.allclose(np.minimum(ob.min(axis=1), sf.min(axis=1)), d, atol=2e-7, rtol=0)
    assert ob.shape == sf.shape == (len(Q), robot.n + 2)
    assert np.all(ob <= 0.3) and np.all(sf <= 0.3)
    # the reported body holds the minimum; self pairs count for both bodies
    hit = c.body >= 0
    rows = np.flatnonzero(hit)
    per = np.where((c.other[hit] >= 0)[:, None], ob[hit], sf[hit])
    assert np.allclose(per[np.arange(len(rows)), c.body[hit]], d[hit], atol=2e-7, rtol=0)
    selfhit = hit & (c.other < 0)
    assert np.allclose(sf[selfhit, -1 - c.other[selfhit]], d[selfhit], atol=2e-7, rtol=0)
    assert np.all(c.body[~hit] == -1) and np.all(c.other[~hit] == -1) and np.isnan(c.point_robot[~hit]).all()
    assert np.all(d[~hit] == 0.3)


def apart_pairs(robot) -> list[tuple[int, int]]:
    """The checked body pairs that are apart at the zero configuration (the default geometry of some
    robots has pairs always touching at a joint: a planner would allow those)."""
    zero = np.zeros(robot.n)
    return [p for p in robot.geometry.checked_pairs(robot.n)
            if model(robot, (), self_pairs=[p], cap=np.inf).clearance(zero) > 0]


@pytest.mark.parametrize("backend", ["kernel", "numpy"])
def test_witness_points_lie_on_the_surfaces(robot, backend):
    """|p_robot − p_other| = |clearance| always; where the pair is apart, both lie on their surfaces
    (in a penetration of a box or a cylinder the robot's point is the segment's deepest point moved by
    the radius along the solid's normal, inside the capsule when the segment is not square to it)."""
    cell = random_cell(5)
    Q = robot.random_configurations(500, seed=6)
    m = (model if backend == "kernel" else fallback)(robot, cell, self_pairs=apart_pairs(robot), cap=np.inf)
    c = m.nearest(Q)
    assert np.allclose(np.linalg.norm(c.point_robot - c.point_other, axis=1), np.abs(c.clearance), atol=1e-6)
    A, B, r, body = ref_capsules(robot.chain, robot.geometry, Q)
    apart = np.flatnonzero(c.clearance > 1e-4)
    assert len(apart) > 20
    for i in apart:
        caps = np.flatnonzero(body == c.body[i])
        gap = point_segment(c.point_robot[i], A[i, caps], B[i, caps]) - r[caps]
        assert np.min(np.abs(gap)) < 1e-6                          # on the surface of one of the body's capsules
        if c.other[i] < 0:
            j = -1 - c.other[i]
            caps = np.flatnonzero(body == j)
            assert np.min(np.abs(point_segment(c.point_other[i], A[i, caps], B[i, caps]) - r[caps])) < 1e-6
        else:
            sh = cell[c.other[i]].shapes[0]
            p = c.point_other[i]
            T = sh.pose
            local = (p - T[:3, 3]) @ T[:3, :3]
            surface = {"sphere": lambda: np.linalg.norm(p - T[:3, 3]) - sh.size[0],
                       "capsule": lambda: point_segment(p, T[:3, 3] - sh.size[1] * T[:3, 2],
                                                        T[:3, 3] + sh.size[1] * T[:3, 2]) - sh.size[0],
                       "box": lambda: sdf_box(local, np.array(sh.size)),
                       "cylinder": lambda: sdf_cylinder(local, sh.size[0], sh.size[1])}[sh.kind]()
            assert abs(surface) < 1e-6, (sh.kind, surface)


@needs_compiler
def test_threads_give_identical_results(robot):
    cell = random_cell(7, spheres=2000)
    Q = robot.random_configurations(5000, seed=8)
    m = model(robot, cell)
    assert np.array_equal(m.clearance(Q, threads=1), m.clearance(Q, threads=2))
    assert m.last_threads == 2
    for call in (m.nearest, m.per_body):
        for x, y in zip(call(Q, threads=1), call(Q, threads=2)):
            assert np.array_equal(x, y, equal_nan=True)


def test_cap():
    robot = kin.load_robot("franka_panda")
    cell = random_cell(9)
    Q = robot.random_configurations(2000, seed=10)
    free = model(robot, cell, cap=np.inf)
    d = free.clearance(Q)
    ob_free, sf_free = free.per_body(Q)
    for cap in (0.5, 0.05, 1e-3):
        m = model(robot, cell, cap=cap)
        assert np.allclose(m.clearance(Q), np.minimum(d, cap), atol=1e-12, rtol=0)
        ob, sf = m.per_body(Q)
        assert np.allclose(ob, np.minimum(ob_free, cap), atol=2e-7, rtol=0) and np.all(ob <= cap)
        assert np.allclose(sf, np.minimum(sf_free, cap), atol=2e-7, rtol=0) and np.all(sf <= cap)
        c = m.nearest(Q)
        assert np.array_equal(c.body == -1, d >= cap)
    nothing = model(robot, (), self_pairs=(), cap=0.7)
    assert np.all(nothing.clearance(Q) == 0.7)
    assert np.all(nothing.per_body(Q)[0] == 0.7) and np.all(nothing.nearest(Q).body == -1)


def test_the_numpy_fallback_warns_once_and_agrees(numpy_backend, robot):
    cell = random_cell(11, spheres=300)
    Q = robot.random_configurations(400, seed=12)
    with pytest.warns(RuntimeWarning, match="numpy"):
        slow = ClearanceModel(robot, obstacles=cell)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ClearanceModel(robot, obstacles=cell)                  # once per process
    assert slow.backend == "numpy"
    ref, _ = ref_clearance(robot.chain, robot.geometry, cell, Q[:100], pairs=slow.self_pairs, cap=1.0)
    d = slow.clearance(Q)
    assert np.all(d[:100] <= ref + ABOVE) and np.all(d[:100] >= ref - BELOW)
    assert slow.clear_one(list(Q[0])) == pytest.approx(d[0], abs=1e-12)
    c = slow.nearest(Q)
    ob, sf = slow.per_body(Q)
    assert np.allclose(np.minimum(ob.min(axis=1), sf.min(axis=1)), d, atol=2e-7, rtol=0)
    assert np.array_equal(c.clearance, d)


@needs_compiler
def test_kernel_and_fallback_agree_in_every_mode(robot):
    cell = random_cell(13, spheres=1000)
    Q = robot.random_configurations(1500, seed=14)
    m, f = model(robot, cell, cap=0.4), fallback(robot, cell, cap=0.4)
    assert np.allclose(m.clearance(Q), f.clearance(Q), atol=2e-7, rtol=0)
    for x, y in zip(m.per_body(Q), f.per_body(Q)):
        assert np.allclose(x, y, atol=2e-7, rtol=0)
    c, cf = m.nearest(Q), f.nearest(Q)
    d = np.sort(np.stack([m.per_body(Q)[0], m.per_body(Q)[1]], axis=1).reshape(len(Q), -1), axis=1)
    clear_win = (d[:, 1] - d[:, 0] > 1e-5) & (c.body >= 0)            # no near tie for the nearest pair
    assert np.array_equal(c.body[clear_win], cf.body[clear_win])
    assert np.array_equal(c.other[clear_win], cf.other[clear_win])
    # (the witness points need not agree: a capsule parallel to a face touches it along a line)
    for w in (c, cf):
        assert np.allclose(np.linalg.norm(w.point_robot - w.point_other, axis=1)[c.body >= 0],
                           np.abs(w.clearance[c.body >= 0]), atol=1e-6)


# ---- chains of every kind ---------------------------------------------------------------------------------
@pytest.mark.parametrize("seed, convention", [(1, "standard"), (2, "modified"), (3, "standard"), (4, "modified")])
def test_random_chains_with_prismatic_joints_and_placements(seed, convention):
    chain = random_chain(seed, n=6, convention=convention, types=("revolute", "prismatic", "revolute", "revolute",
                                                                   "prismatic", "revolute"))
    geometry = kin.geometry.default_geometry(chain)
    rng = np.random.default_rng(seed)
    base = pose(rng, (0.1, -0.2, 0.3))
    cell = random_cell(seed + 20)
    Q = rng.uniform(chain.lower, chain.upper, (300, chain.n))
    pairs = geometry.checked_pairs(chain.n)
    m = model(chain, cell, geometry=geometry, base=base, cap=np.inf)
    assert m.self_pairs == tuple(pairs)
    ref, _ = ref_clearance(chain, geometry, cell, Q, base=base, pairs=pairs)
    d = m.clearance(Q)
    assert np.all(d <= ref + ABOVE), float((d - ref).max())
    assert np.all(d >= ref - BELOW), float((ref - d).max())
    assert np.allclose(body_frames(chain, Q, base), ref_frames(chain, Q, base), atol=1e-12)
    assert np.allclose(fallback(chain, cell, geometry=geometry, base=base, cap=np.inf).clearance(Q), d, atol=2e-7)


def test_huge_joint_angles_take_the_exact_path():
    robot = kin.load_robot("franka_panda")
    cell = random_cell(15)
    Q = robot.random_configurations(64, seed=16)
    turns = np.zeros_like(Q)
    turns[::2, 0] = 2 * math.pi * 1e6                       # beyond the vector sin/cos's reduction
    m = model(robot, cell, cap=np.inf)
    ref, _ = ref_clearance(robot.chain, robot.geometry, cell, Q + turns, pairs=m.self_pairs)
    d = m.clearance(Q + turns)
    assert np.all(d <= ref + 1e-9) and np.all(d >= ref - BELOW)
    assert np.allclose(d, m.clearance(Q), atol=1e-8)


# ---- one pair at a time -------------------------------------------------------------------------------------
ONE = Chain(name="one joint", joints=(Joint("revolute"),))


def capsule_model(a, b, r, shapes, cap=np.inf) -> ClearanceModel:
    """A capsule fixed to the base (body 0 = the world, q irrelevant) against ``shapes``."""
    return model(ONE, [Obstacle("it", tuple(shapes))], geometry=RobotGeometry((LinkCapsule(0, a, b, r),)),
                 self_pairs=(), cap=cap)


@pytest.mark.parametrize("kind", ["sphere", "capsule", "box", "cylinder"])
def test_random_pairs_against_the_reference(kind):
    rng = np.random.default_rng(hash(kind) % 1000)
    for _ in range(150):
        size = tuple(float(x) for x in rng.uniform(0.02, 0.3, 3))
        size = {"sphere": (size[0], 0, 0), "box": size}.get(kind, (size[0], size[1], 0))
        sh = Shape(kind, size, pose(rng, (0, 0, 0), 0.2))
        a = rng.uniform(-0.5, 0.5, 3)
        b = a + (rng.normal(size=3) * rng.uniform(0, 0.5) if rng.uniform() < 0.8 else 0.0)
        r = float(rng.uniform(0, 0.1))
        m = capsule_model(a, b, r, [sh])
        v = m.clearance(np.zeros(1))
        ref = float(ref_pair(a[None], b[None], np.array([r]), sh)[0])
        assert ref - BELOW <= v <= ref + ABOVE, (kind, v, ref)


def test_grazing_and_barely_penetrating_pairs():
    rng = np.random.default_rng(17)
    for eps in (1e-3, 1e-6, 1e-8, 0.0, -1e-8, -1e-6):
        for kind in ("sphere", "capsule", "box", "cylinder"):
            T = pose(rng, (0, 0, 0))
            r = 0.03
            # a segment tangent to a face/side, eps outside (along the local normal n, tangent u)
            if kind == "box":
                size, n, u, p0 = (0.2, 0.15, 0.1), np.array([0, 0, 1.0]), np.array([1.0, 0.3, 0]), np.array([0, 0, 0.1])
            elif kind == "cylinder":
                size, n, u, p0 = (0.1, 0.2, 0), np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), np.array([0.1, 0, 0])
            elif kind == "capsule":
                size, n, u, p0 = (0.05, 0.2, 0), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0.05, 0, 0])
            else:
                size, n, u, p0 = (0.1, 0, 0), np.array([0, 0, 1.0]), np.array([1.0, 0, 0]), np.array([0, 0, 0.1])
            u = u / np.linalg.norm(u)
            mid = p0 + (eps + r) * n
            a_l, b_l = mid - 0.05 * u, mid + 0.05 * u
            if kind == "sphere":
                a_l = b_l = mid
            a, b = (T[:3, :3] @ x + T[:3, 3] for x in (a_l, b_l))
            v = capsule_model(a, b, r, [Shape(kind, size, T)]).clearance(np.zeros(1))
            assert eps - BELOW <= v <= eps + ABOVE, (kind, eps, v)
            if eps < 0:
                assert v < 0
            if eps > BELOW:
                assert v > 0


def test_near_parallel_segments_stay_below_the_truth():
    rng = np.random.default_rng(18)
    for angle in (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 0.0):
        for gap in (0.0, 1e-7, 0.01):
            R = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
            # segment 1 along x; segment 2 turned by `angle` about the z axis through x = 0.3, `gap` above:
            # they cross (in projection) at x = 0.3, where the distance is exactly `gap`
            a1, b1 = np.array([0.0, 0, 0]), np.array([0.6, 0, 0])
            d = np.array([math.cos(angle), math.sin(angle), 0.0])
            a2, b2 = np.array([0.3, 0, gap]) - 0.25 * d, np.array([0.3, 0, gap]) + 0.25 * d
            t = rng.uniform(-0.5, 0.5, 3)
            w = lambda x: R @ x + t
            m = model(ONE, geometry=RobotGeometry((LinkCapsule(0, w(a1), w(b1), 0.01),
                                                   LinkCapsule(2, w(a2), w(b2), 0.02))),
                      self_pairs=[(0, 2)], cap=np.inf)
            Q = np.zeros((1, 1))
            v = m.clearance(Q)[0]
            # body 2 of a one-joint chain is the tool: its frame is frame 1 = frame 0 at q = 0
            truth = gap - 0.03
            assert truth - BELOW <= v <= truth + ABOVE, (angle, gap, v - truth)


def test_sphere_sets_match_brute_force():
    robot = kin.load_robot("fanuc_lrmate200id")
    rng = np.random.default_rng(19)
    K = 100_000
    S = np.column_stack([rng.uniform((-0.6, -0.6, 0.0), (0.6, 0.6, 0.9), (K, 3)), rng.uniform(0.001, 0.01, K)])
    node, link, leafs, rep = sphere_tree(S)
    assert sorted(map(tuple, leafs)) == sorted(map(tuple, S))             # a permutation of the spheres
    ranges = _ranges(link)
    assert tuple(ranges[0]) == (0, K)
    leaves = np.flatnonzero(link[:, 1] < 0)
    some = np.concatenate([leaves, rng.choice(len(node), 300, replace=False), [0]])
    for k in some:                                                         # every ball holds its spheres
        lo, hi = ranges[k]
        inside = np.linalg.norm(leafs[lo:hi, :3] - node[k, :3], axis=1) + leafs[lo:hi, 3]
        assert inside.max() <= node[k, 3]
        assert lo <= rep[k] < hi
    cloud = [Obstacle("cloud", spheres=S, ignore={0})]
    Q = robot.random_configurations(40, seed=20)
    m = model(robot, cloud, self_pairs=(), cap=np.inf)
    d = m.clearance(Q)
    A, B, r, body = ref_capsules(robot.chain, robot.geometry, Q)
    brute = np.full(len(Q), np.inf)
    for c in np.flatnonzero(body != 0):
        for i in range(len(Q)):
            brute[i] = min(brute[i], float((point_segment(S[:, :3], A[i, c], B[i, c]) - r[c] - S[:, 3]).min()))
    assert np.allclose(d, brute, atol=1e-12, rtol=0)
    assert np.allclose(fallback(robot, cloud, self_pairs=(), cap=np.inf).clearance(Q), brute, atol=1e-12, rtol=0)
    assert np.allclose(model(robot, cloud, self_pairs=(), cap=0.02).clearance(Q), np.minimum(brute, 0.02),
                       atol=1e-12, rtol=0)


def _ranges(link) -> np.ndarray:
    """(M, 2) the leaf-order range of the spheres under each node (children come after their parents)."""
    out = np.zeros((len(link), 2), np.int64)
    for k in range(len(link) - 1, -1, -1):
        if link[k, 1] < 0:
            out[k] = link[k, 0], link[k, 0] - link[k, 1]
        else:
            out[k] = out[link[k, 0], 0], out[link[k, 1], 1]
    return out


def test_ignore_sets_and_self_pairs():
    robot = kin.load_robot("franka_panda")
    n, B = robot.n, robot.n + 2
    cell = random_cell(21)
    Q = robot.random_configurations(500, seed=22)
    base = model(robot, cell, self_pairs=(), cap=np.inf)
    ob, sf = base.per_body(Q)
    assert np.all(np.isinf(sf))
    ignoring = [Obstacle(o.name, o.shapes, o.spheres, ignore=o.ignore | {0, 3, n + 1}) for o in cell]
    ob2, _ = model(robot, ignoring, self_pairs=(), cap=np.inf).per_body(Q)
    assert np.all(np.isinf(ob2[:, [0, 3, n + 1]]))
    keep = [b for b in range(B) if b not in (0, 3, n + 1)]
    assert np.allclose(ob2[:, keep], ob[:, keep], atol=2e-7, rtol=0)
    everything = [Obstacle(o.name, o.shapes, ignore=set(range(B))) for o in cell]
    assert np.all(model(robot, everything, self_pairs=(), cap=0.2).clearance(Q) == 0.2)
    # self pairs: a chosen pair against the reference, counted for both bodies
    pairs = [(1, 5), (3, 7), (0, 6)]
    m = model(robot, (), self_pairs=[(5, 1), (3, 7), (0, 6), (3, 7)], cap=np.inf)
    assert m.self_pairs == ((0, 6), (1, 5), (3, 7))
    ref, _ = ref_clearance(robot.chain, robot.geometry, (), Q, pairs=pairs)
    d = m.clearance(Q)
    assert np.all(d <= ref + ABOVE) and np.all(d >= ref - BELOW)
    _, sf = m.per_body(Q)
    for i, j in pairs:
        other = [p for p in pairs if p != (i, j) and (i in p or j in p)]
        if not other:
            assert np.array_equal(sf[:, i], sf[:, j])
    assert np.all(np.isinf(sf[:, [2, 4, 8]]))
    c = m.nearest(Q)
    assert set(np.unique(c.other)) <= {-1 - j for _, j in pairs}
    assert model(robot).self_pairs == tuple(robot.geometry.checked_pairs(n))
    fanuc = kin.load_robot("fanuc_lrmate200id")                            # its tool (body 7) holds no capsule
    assert model(fanuc, self_pairs=[(2, 7), (2, 4)]).self_pairs == ((2, 4),)


def test_single_configurations():
    robot = kin.load_robot("fanuc_lrmate200id")
    cell = random_cell(23)
    m = model(robot, cell)
    Q = robot.random_configurations(20, seed=24)
    d = m.clearance(Q)
    for i, q in enumerate(Q):
        assert isinstance(m.clearance(q), float) and m.clearance(q) == d[i]
        assert m.clear_one(list(map(float, q))) == pytest.approx(d[i], abs=1e-12)
        assert m.clear_one(q) == pytest.approx(d[i], abs=1e-12)
        c = m.nearest(q)
        assert isinstance(c.body, int) and isinstance(c.clearance, float) and c.point_robot.shape == (3,)
        ob, sf = m.per_body(q)
        assert ob.shape == sf.shape == (robot.n + 2,)
    assert m.clearance(np.zeros((0, robot.n))).shape == (0,)


# ---- invalid input ------------------------------------------------------------------------------------------
def _bad_capsule(radius):
    return RobotGeometry((LinkCapsule(1, (0, 0, 0), (0, 0, 0.1), radius),))


@pytest.mark.parametrize("kwargs, cls, words", [
    (dict(geometry=_bad_capsule(-0.01)), GeometryError, "radius"),
    (dict(geometry=_bad_capsule(math.nan)), GeometryError, "radius"),
    (dict(geometry=RobotGeometry((LinkCapsule(9, (0, 0, 0), (0, 0, 0), 0.1),))), GeometryError, "body 9"),
    (dict(geometry=RobotGeometry((LinkCapsule(1, (0, 0, math.inf), (0, 0, 0), 0.1),))), GeometryError,
     "non-finite"),
    (dict(obstacles=[Shape("box", (0.1, -0.1, 0.1))]), GeometryError, "size"),
    (dict(obstacles=[Shape("sphere", (math.nan, 0, 0))]), GeometryError, "size"),
    (dict(obstacles=[Shape("box", (0.1, 0.1, 0.1), np.diag([1.0, 2.0, 1.0, 1.0]))]), GeometryError, "rigid"),
    (dict(obstacles=[Obstacle("cloud", spheres=np.array([[0, 0, 0, -1.0]]))]), GeometryError, "radius"),
    (dict(obstacles=[Obstacle("cloud", spheres=np.array([[0, 0, math.nan, 1.0]]))]), GeometryError, "non-finite"),
    (dict(obstacles=[Obstacle("o", ignore={12})]), GeometryError, "ignores body 12"),
    (dict(obstacles=["box"]), ArgumentError, "obstacles[0]"),
    (dict(obstacles=3), ArgumentError, "obstacles"),
    (dict(self_pairs=[(1, 1)]), GeometryError, "self_pairs"),
    (dict(self_pairs=[(1, 20)]), GeometryError, "self_pairs"),
    (dict(self_pairs=[1]), ArgumentError, "self_pairs"),
    (dict(cap=-1.0), ArgumentError, "cap"),
    (dict(cap=math.nan), ArgumentError, "cap"),
    (dict(cap="1"), ArgumentError, "cap"),
    (dict(threads=0), ArgumentError, "threads"),
    (dict(threads=1.5), ArgumentError, "threads"),
    (dict(base=np.eye(3)), GeometryError, "base"),
    (dict(base=np.full((4, 4), math.nan)), GeometryError, "base"),
    (dict(geometry="capsules"), ArgumentError, "geometry"),
])
def test_invalid_arguments_raise_one_clear_line(kwargs, cls, words):
    robot = kin.load_robot("fanuc_lrmate200id")
    with pytest.raises(cls) as e:
        ClearanceModel(robot, **kwargs)
    assert isinstance(e.value, RmtError) and isinstance(e.value, ValueError)
    assert words in str(e.value) and "\n" not in str(e.value)


def test_sphere_sets_must_be_k_by_4():
    for S in (np.ones((4, 3)), np.ones(8), np.ones((2, 4, 1))):
        with pytest.raises(GeometryError, match=r"\(K, 4\)"):
            Obstacle("cloud", spheres=S)


def test_invalid_configurations():
    robot = kin.load_robot("fanuc_lrmate200id")
    m = model(robot, random_cell(25))
    for q in (np.full(6, math.nan), np.zeros(5), np.zeros((3, 7)), [[0.0] * 6, [0.0] * 5], ["a"] * 6,
              [0, 0, math.inf, 0, 0, 0]):
        for call in (m.clearance, m.nearest, m.per_body, m.clear_one):
            with pytest.raises(ConfigurationError) as e:
                call(q)
            assert "\n" not in str(e.value)
    with pytest.raises(ArgumentError, match="threads"):
        m.clearance(np.zeros(6), threads=-2)
    # a prismatic value beyond the range any prismatic joint may take: the single call's C check sends it
    # to the validating path
    chain = random_chain(5, n=3, types=("revolute", "prismatic", "revolute"))
    p = model(chain, random_cell(26))
    q = [0.1, 0.0, 0.2]
    assert p.clear_one(q) == pytest.approx(p.clearance(np.array(q)), abs=1e-12)
    for bad in ([0.1, 1e9, 0.2], [0.1, math.nan, 0.2]):
        with pytest.raises(ConfigurationError, match="joint 2"):
            p.clear_one(bad)
    with pytest.raises(ArgumentError, match="chain"):
        ClearanceModel("puma")
