"""The collision geometry of the bundled robots (kin/robots/*.toml, [geometry]).

* Every arm with geometry: it loads with positive radii and a stated source, each capsule overlaps its
  body's DH links (the default capsules of that body: nothing sits absurdly far off), the file saves
  and loads back identically, and at its home (q = 0 within the limits; the Panda's ready pose) no two
  checked bodies' capsules meet (segment distances in plain numpy).
* The Panda's capsules are re-derived from example-robot-data's collision meshes
  (tests/kin/geometry/bundled_fit.py, the generator of all the mesh-fitted arms) and hold every vertex
  of those meshes at random configurations, placed by the URDF's own kinematics (yourdfpy).
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import kin
from kin.geometry import body_frames, chain_length, default_geometry
from kin.geometry.enclose import segment_distance
from kin.robotfile import dumps_robot, loads_robot
from tests.kin.geometry.bundled_fit import fit, rounded, segment_segment
from tests.kin.urdf.reference import erd_urdf

WITH_GEOMETRY = ["abb_irb120", "fanuc_lrmate200id", "fanuc_m16ib20", "franka_panda", "kinova_gen3", "kuka_iiwa14",
                 "kuka_iiwa7", "puma560", "stanford_arm", "ur10e", "ur16e", "ur3e", "ur5e"]
#: a documented home where q = 0 is outside the limits or not the arm's rest pose
HOME = {"franka_panda": [0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4]}


def home(chain) -> np.ndarray:
    return np.array(HOME.get(chain.name, np.clip(np.zeros(chain.n), chain.lower, chain.upper)), dtype=float)


def placed(chain, q):
    F = body_frames(chain, q)[0]
    out = []
    for c in chain.geometry.capsules:
        R, p = F[c.body, :3, :3], F[c.body, :3, 3]
        out.append((c.body, R @ np.array(c.a) + p, R @ np.array(c.b) + p, c.radius))
    return out


def test_the_real_arms_have_geometry_and_the_toys_defaults():
    have = [n for n in kin.bundled_robots() if kin.load_chain(n).geometry is not None]
    assert have == WITH_GEOMETRY


@pytest.mark.parametrize("name", WITH_GEOMETRY)
def test_geometry_loads_with_a_source(name):
    chain = kin.load_chain(name)
    g = chain.geometry
    assert len(g.source) > 100 and g.radius is None
    assert g.capsules and all(c.radius > 0 for c in g.capsules)
    assert 0 < g.over_estimate < 0.2
    bodies = {c.body for c in g.capsules}
    assert set(range(1, chain.n + 1)) <= bodies and bodies <= set(range(chain.n + 2))
    assert all(j - i > 1 for i, j in g.allowed)
    assert kin.Robot(chain).geometry is g


@pytest.mark.parametrize("name", WITH_GEOMETRY)
def test_capsules_sit_on_their_links(name):
    """At home and at random configurations, every capsule of body k comes within a tenth of the arm's
    length of a default capsule (the DH links, 5 % of the arm's length thick) of body k or of a
    neighbour (a piece along joint k + 1's axis goes with body k + 1 in the default geometry, whatever
    turns about it; real links sit beside the DH lines, as UR's upper arm does, 120 to 180 mm), and
    none is larger than half the arm."""
    chain = kin.load_chain(name)
    L = chain_length(chain)
    skeleton = replace(chain, geometry=default_geometry(chain))
    for c in chain.geometry.capsules:
        assert c.radius < 0.5 * L and c.length < L, c
    for q in [home(chain), *np.random.default_rng(1).uniform(chain.lower, chain.upper, size=(5, chain.n))]:
        bones = placed(skeleton, q)
        for c, (body, a, b, r) in zip(chain.geometry.capsules, placed(chain, q)):
            gap = min(segment_segment(a, b, a2, b2) - r - r2 for b_, a2, b2, r2 in bones if abs(b_ - body) <= 1)
            assert gap <= 0.1 * L, (c, gap)


@pytest.mark.parametrize("name", WITH_GEOMETRY)
def test_file_round_trip(name):
    chain = kin.load_chain(name)
    again = loads_robot(dumps_robot(chain))
    assert again == chain


@pytest.mark.parametrize("name", WITH_GEOMETRY)
def test_no_self_collision_at_home(name):
    chain = kin.load_chain(name)
    g = chain.geometry
    q = home(chain)
    assert chain.within_limits(q)
    caps = placed(chain, q)
    pairs = g.checked_pairs(chain.n)
    assert pairs
    for i, j in pairs:
        gap = min(segment_segment(a1, b1, a2, b2) - r1 - r2
                  for bi, a1, b1, r1 in caps if bi == i for bj, a2, b2, r2 in caps if bj == j)
        assert gap > 0, f"bodies {i} and {j} meet at home (gap {gap:.4f} m)"


def test_segment_distance_helper():
    """The numpy segment distance of these tests against brute-force sampling."""
    rng = np.random.default_rng(0)
    t = np.linspace(0, 1, 401)
    for _ in range(50):
        p1, q1, p2, q2 = rng.normal(size=(4, 3))
        if rng.uniform() < 0.2:
            q2 = p2 + (q1 - p1) * rng.uniform(0.5, 2)          # parallel
        A = p1 + t[:, None] * (q1 - p1)
        B = p2 + t[:, None] * (q2 - p2)
        brute = np.linalg.norm(A[:, None] - B[None], axis=2).min()
        assert segment_segment(p1, q1, p2, q2) <= brute + 1e-12
        assert segment_segment(p1, q1, p2, q2) >= brute - 0.02


# ---- the Panda, re-derived from example-robot-data -------------------------------------------------
PANDA = "panda_description/urdf/panda.urdf"


def test_panda_capsules_are_those_of_the_meshes():
    path = erd_urdf(PANDA)
    caps, over = fit("franka_panda", str(path), "panda_link8")
    bundled = kin.load_chain("franka_panda").geometry
    again = rounded(caps, 1e-4)
    assert len(again) == len(bundled.capsules)
    for c, b in zip(again, bundled.capsules, strict=True):
        assert (c.body, c.name) == (b.body, b.name)
        np.testing.assert_allclose([*c.a, *c.b, c.radius], [*b.a, *b.b, b.radius], atol=1e-9)
    assert over <= bundled.over_estimate <= over + 1e-3


def test_panda_capsules_hold_the_meshes():
    import trimesh
    import yourdfpy
    path = erd_urdf(PANDA)
    chain = kin.load_chain("franka_panda")
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    robots = path.parents[2]
    meshes = []
    for k in range(8):
        link = model.link_map[f"panda_link{k}"]
        for col in link.collisions:
            name = col.geometry.mesh.filename.split("robots/", 1)[1]
            V = np.asarray(trimesh.load(str(robots / name), force="mesh").vertices)
            meshes.append((k, f"panda_link{k}", np.eye(4) if col.origin is None else col.origin, V))
    assert len(meshes) == 8
    names = [j.name for j in chain.joints]
    urdf_names = [f"panda_joint{i}" for i in range(1, 8)]
    for q in [home(chain), *np.random.default_rng(3).uniform(chain.lower, chain.upper, size=(6, chain.n))]:
        model.update_cfg(dict(zip(urdf_names, q)))
        caps = placed(chain, q)
        for body, link, origin, V in meshes:
            T = np.asarray(model.get_transform(link, "panda_link0")) @ origin
            P = V @ T[:3, :3].T + T[:3, 3]
            d = np.full(len(P), np.inf)
            for b, a, e, r in caps:
                if b == body:
                    d = np.minimum(d, segment_distance(P, a, e) - r)
            assert d.max() <= 1e-9, (link, names, float(d.max()))
