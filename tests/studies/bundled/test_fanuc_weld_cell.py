"""The weld-cell study in quick mode, checked against independent values: the LR Mate's frames by a
numpy DH product typed in from its robot file, the cell's boxes and column typed in from its cell
file, and every distance computed by coal (capsule against box, cylinder and capsule; signed, so a
collision is a negative distance) or, for the part's spheres, by plain numpy — then strict JSON and
the report in headless Chromium."""
from __future__ import annotations

import math

import coal
import numpy as np
import pytest
import trimesh

import kin
from design.task import load_task
from planning.cell import load_cell
from planning.collision import collision_world
from tests.dh_numpy import dh_standard
from tests.studies.bundled.common import ROOT, assert_report_holds, assert_report_renders, quick_run

CELL_FILE = ROOT / "studies" / "cells" / "fanuc_weld_cell.toml"
#: kin/robots/fanuc_lrmate200id.toml: rows (a m, α deg, d m, θ offset deg); tool rpy = (180°, 0, 0)
DH = [(0.050, -90, 0.330, 0), (0.330, 180, 0.0, -90), (0.035, -90, 0.0, 0), (0.0, 90, -0.335, 0),
      (0.0, -90, 0.0, 0), (0.0, 0, -0.080, 0)]
#: the cell file: the robot's base on the table top, 800 mm above the floor
BASE = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.8], [0, 0, 0, 1.0]])
TOOL = np.diag([1.0, -1.0, -1.0, 1.0])                 # Rx(180°)
#: the cell file's primitive obstacles (m): name, kind, centre, size (box: full edges; cylinder: radius, length),
#: the bodies that may touch it (0 base, k link k, 7 the tool)
PRIMITIVES = [("table", "box", (0.4, 0.0, 0.78), (1.4, 0.9, 0.04), {0, 1}),
              ("fixture", "box", (0.55, 0.0, 0.85), (0.3, 0.2, 0.1), set()),
              ("wire feeder column", "cylinder", (-0.25, -0.55, 0.9), (0.08, 1.8), set()),
              ("rear fence", "box", (-0.9, 0.0, 1.0), (0.02, 2.4, 2.0), set()),
              ("floor", "box", (0.0, 0.0, -0.01), (4.0, 4.0, 0.02), set())]
#: the seam: the pipe (outer radius 50 mm, axis along y through x 550, z 950 mm) meets the flange's face at y = 113 mm
SEAM_C, SEAM_R = np.array([0.55, 0.113, 0.95]), 0.05
#: the torch tip in the tool frame: the far end of the cell's torch neck, (0, 40, 310) mm
TIP = np.array([0.0, 0.04, 0.31])


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return quick_run("fanuc_weld_cell", tmp_path_factory)


@pytest.fixture(scope="module")
def world():
    """The capsules and the allowed pairs are the study's model; the distances below are not."""
    return collision_world(kin.load_robot("fanuc_lrmate200id"), load_cell(CELL_FILE))


def frames(q) -> list[np.ndarray]:
    """Bodies 0 … 7 in the cell: base, links 1 … 6, tool (numpy DH product)."""
    T, out = BASE.copy(), [BASE.copy()]
    for (a, alpha, d, off), qi in zip(DH, q):
        T = T @ dh_standard(qi + math.radians(off), d, a, math.radians(alpha))
        out.append(T)
    out.append(T @ TOOL)
    return out


def _tf(R, t):
    return coal.Transform3s(np.asarray(R, float), np.asarray(t, float))


def capsules(world, q) -> list[tuple[int, object, object, np.ndarray, np.ndarray, float]]:
    """(body, coal geometry, transform, a, b, radius) of every capsule, placed at q (world frame)."""
    F = frames(q)
    out = []
    for c in world.geometry.capsules:
        M = F[c.body]
        a, b = M[:3, :3] @ c.a + M[:3, 3], M[:3, :3] @ c.b + M[:3, 3]
        L = float(np.linalg.norm(b - a))
        if L < 1e-12:
            out.append((c.body, coal.Sphere(c.radius), _tf(np.eye(3), a), a, b, c.radius))
            continue
        z = (b - a) / L
        x = np.cross([0.0, 0.0, 1.0] if abs(z[2]) < 0.9 else [1.0, 0.0, 0.0], z)
        x /= np.linalg.norm(x)
        R = np.column_stack([x, np.cross(z, x), z])
        out.append((c.body, coal.Capsule(c.radius, L), _tf(R, 0.5 * (a + b)), a, b, c.radius))
    return out


OBSTACLES = [(name, coal.Box(*size) if kind == "box" else coal.Cylinder(*size), _tf(np.eye(3), centre), ignore)
             for name, kind, centre, size, ignore in PRIMITIVES]


def distance(g1, t1, g2, t2) -> float:
    return coal.distance(g1, t1, g2, t2, coal.DistanceRequest(), coal.DistanceResult())


def sphere_clearance(a, b, r, S) -> float:
    """The clearance of capsule a–b of radius r to spheres S (K, 4), numpy."""
    if len(S) == 0:
        return math.inf
    ab = b - a
    t = np.clip((S[:, :3] - a) @ ab / max(float(ab @ ab), 1e-300), 0.0, 1.0)
    return float((np.linalg.norm(S[:, :3] - (a + t[:, None] * ab), axis=1) - S[:, 3]).min() - r)


def clearances(world, q, part_spheres) -> dict:
    """Every checked distance at q: (body, obstacle name) → clearance, and (body, body) for the self pairs."""
    caps = capsules(world, q)
    out = {}
    for body, g, t, a, b, r in caps:
        for name, og, ot, ignore in OBSTACLES:
            if body not in ignore:
                d = distance(g, t, og, ot)
                out[(body, name)] = min(out.get((body, name), math.inf), d)
        if body != 7:                                   # the torch may touch the part it welds
            out[(body, "part")] = min(out.get((body, "part"), math.inf), sphere_clearance(a, b, r, part_spheres))
    for i, j in world.pairs:
        for bi, gi, ti, *_ in caps:
            for bj, gj, tj, *_ in caps:
                if (bi, bj) == (i, j):
                    out[(i, j)] = min(out.get((i, j), math.inf), distance(gi, ti, gj, tj))
    return out


def dense(path: np.ndarray, step: float) -> np.ndarray:
    """States along the joint path with no joint moving more than ``step`` (rad) between them."""
    out = []
    for a, b in zip(path[:-1], path[1:]):
        k = max(1, int(np.ceil(np.abs(b - a).max() / step)))
        out.append(a + np.linspace(0.0, 1.0, k, endpoint=False)[:, None] * (b - a))
    return np.vstack(out + [path[-1:]])


def test_study_ran_ok_and_json_is_strict(run):
    d = run.results
    assert run.copied.returncode == 0 and d["ok"] is True and d["quick"] is True and d["study"] == "fanuc_weld_cell"
    assert len(d["findings"]) == 4 and all(f["ok"] for f in d["findings"])
    for png in ("j2_j3_map.png", "seam.png", "clearance.png"):
        assert (run.report.parent / png).stat().st_size > 10_000, png
    assert {"windows_only_plan.csv", "cell_aware_plan.csv"} <= set(d["meta"]["files"])
    assert d["cell"]["base"] == pytest.approx([0.0, 0.0, 0.8])
    assert d["cell"]["torch_tip"] == pytest.approx(TIP.tolist(), abs=1e-12)


def test_frames_are_the_robot_files(world):
    robot = world.robot
    for q in np.random.default_rng(2).uniform(robot.chain.lower, robot.chain.upper, (20, 6)):
        np.testing.assert_allclose(BASE @ robot.fk(q), frames(q)[-1], atol=1e-12)
    assert frames(np.zeros(6))[-1][:3, 3] == pytest.approx([0.465, 0.0, 0.8 + 0.695])    # docs/cells.md


def test_the_design_task_is_out_of_the_lrmates_reach(run, world):
    # the LR Mate reaches at most |a1| + |a2| + √(a3² + d4²) + |d6| from joint 1's axis (its robot file's
    # DH rows); every target of studies/tasks/fanuc_weld_cell.toml lies farther from that axis
    a, _, d, _ = world.robot.chain.dh_table().T
    reach = abs(a[0]) + abs(a[1]) + math.hypot(a[2], d[3]) + abs(d[5])
    assert reach == pytest.approx(0.05 + 0.33 + math.hypot(0.035, 0.335) + 0.08, abs=1e-12)
    targets = load_task(ROOT / "studies" / "tasks" / "fanuc_weld_cell.toml").targets.positions
    assert np.hypot(targets[:, 0], targets[:, 1]).min() > reach
    t = run.results["cell"]["design_task"]
    assert t["targets"] == 27 and t["reached_by_lrmate"] == 0


def test_self_collision_is_a_capsule_overlap_coal_sees(run, world):
    sc = run.results["self_collision"]
    ex = sc["example"]
    i, j = ex["bodies"]
    caps = capsules(world, ex["q"])
    d = min(distance(gi, ti, gj, tj) for bi, gi, ti, *_ in caps for bj, gj, tj, *_ in caps if (bi, bj) == (i, j))
    assert d < 0 and d == pytest.approx(ex["clearance"], abs=1e-5)
    assert ex["q"][1] == 0.0 and world.robot.chain.lower[2] < ex["q"][2] < 0
    # where folding J3 starts to collide: one 0.1° step before it every checked pair is clear, at it one is not
    fold = sc["fold"]["down"]
    q = np.array(fold["q"])
    own = lambda q: min(v for k, v in clearances(world, q, np.zeros((0, 4))).items() if isinstance(k[1], int))  # noqa: E731
    before = q.copy()
    before[2] += math.radians(0.1)
    assert own(q) <= 1e-7 and own(before) > -1e-7
    assert 0 < sc["self_fraction"] < 1 and sc["pairs"][0]["count"] >= sc["pairs"][-1]["count"]


def test_the_seam_targets_and_the_clear_weld_poses(run, world):
    s = run.results["seam"]
    P, A, phi = np.array(s["positions"]), np.array(s["axes"]), np.array(s["phi"])
    assert len(P) == s["points"] == 36
    # on the circle where the pipe meets the flange, which is an edge of the part's mesh
    np.testing.assert_allclose(np.hypot(P[:, 0] - SEAM_C[0], P[:, 2] - SEAM_C[2]), SEAM_R, atol=1e-12)
    assert np.allclose(P[:, 1], SEAM_C[1])
    V = trimesh.load_mesh(ROOT / "studies" / "cells" / "weld_part.stl").vertices / 1000     # mm; rpy (90, 0, 0)
    V = np.column_stack([V[:, 0], -V[:, 2], V[:, 1]]) + [0.55, 0.0, 0.95]
    ring = np.isclose(np.hypot(V[:, 0] - 0.55, V[:, 2] - 0.95), SEAM_R) & np.isclose(V[:, 1], SEAM_C[1])
    assert ring.sum() >= 16
    # the torch at 45° between the pipe's surface and the flange's face, pointing into the corner
    radial = np.column_stack([np.cos(phi), np.zeros_like(phi), np.sin(phi)])
    np.testing.assert_allclose(A, (np.array([0, 1.0, 0]) - radial) / math.sqrt(2), atol=1e-12)
    # every weld pose reached clear puts the torch tip on its seam point, along its axis, and is clear by coal
    clear = np.array(s["pose_clear"]).reshape(36, s["rolls"])
    Q = np.array(s["q_clear"]).reshape(36, s["rolls"], 6)
    assert np.array_equal(clear.any(axis=1), s["clear"])
    part = world.obstacles[2].spheres
    for i, k in zip(*np.nonzero(clear)):
        F = frames(Q[i, k])[-1]
        np.testing.assert_allclose(F[:3, :3] @ TIP + F[:3, 3], P[i], atol=2e-4)
        np.testing.assert_allclose(F[:3, :3] @ (TIP - [0, 0, 0.2]) / np.linalg.norm(TIP - [0, 0, 0.2]), A[i],
                                   atol=2e-3)
        assert min(clearances(world, Q[i, k], part).values()) >= 0.010 - 1e-6
    reached, cl, removed = (np.array(s[k]) for k in ("reached", "clear", "removed"))
    assert np.array_equal(removed, reached & ~cl) and not (cl & ~reached).any()
    assert f"IK reaches {reached.sum()} of the seam's 36 points; collisions remove {removed.sum()}" \
        in run.results["findings"][1]["text"]
    assert removed.sum() > 0 and cl.sum() > 0
    # the top of the seam is clear, its bottom only through a collision or out of reach
    top, bottom = np.abs(phi - math.pi / 2) < 0.3, np.abs(phi - 3 * math.pi / 2) < 0.3
    assert cl[top].all() and not cl[bottom].any()


def test_the_windows_only_plan_drives_a_link_into_the_cell(run, world):
    m = run.results["move"]
    w = m["windows_only"]
    assert w["success"] and w["proven"] and w["check"]["windows_check"] == "proven"
    c = w["cell_check"]
    assert c["valid"] is False and c["first_violation"]["kind"] == "collision" and c["collision_check"] == "proven"
    deep = w["deepest"]
    body, name = deep["body"], world.obstacles[deep["other"]].name
    # the forearm (body 4, which carries the 335 mm d4 offset) into the wire-feeder column, as the study says
    assert (body, name) == (4, "wire feeder column")
    assert f"link {body}" in run.results["findings"][2]["text"] and name in run.results["findings"][2]["text"]
    caps = capsules(world, deep["q"])
    ob = next(o for o in OBSTACLES if o[0] == name)
    d = min(distance(g, t, ob[1], ob[2]) for b, g, t, *_ in caps if b == body)
    assert d < -0.05 and d == pytest.approx(deep["clearance"], abs=1e-5)
    assert w["numpy_clearance"] == pytest.approx(d, abs=1e-4)
    # the deepest point lies on the path: the plan's own segment, interpolated
    P = np.array(w["path"])
    assert P[0] == pytest.approx(m["start"]) and P[-1] == pytest.approx(m["goal"])
    assert np.sign(m["start"][4]) == np.sign(m["goal"][4])                # no wrist flip on the way
    t = np.linspace(0, 1, 20001)
    S = np.concatenate([a + t[:, None] * (b - a) for a, b in zip(P[:-1], P[1:])])
    assert np.linalg.norm(S - deep["q"], axis=1).min() < 1e-3
    # start and goal are clear (by coal), so the collision is the move's
    part = world.obstacles[2].spheres
    assert min(clearances(world, P[0], part).values()) > 0.01 and min(clearances(world, P[-1], part).values()) >= 0.01


def test_the_cell_aware_plan_is_clear_by_coal(run, world):
    m = run.results["move"]
    a = m["cell_aware"]
    assert a["success"] and a["proven"] and a["check"]["collision_check"] == "proven"
    assert a["check"]["windows_check"] == "proven" and a["check"]["valid"] is True
    P = np.array(a["path"])
    assert P[0] == pytest.approx(m["start"]) and P[-1] == pytest.approx(m["goal"])
    part = world.obstacles[2].spheres
    Q = dense(P, math.radians(0.5))
    mins = np.array([min(clearances(world, q, part).values()) for q in Q])
    assert mins.min() >= 0.010 - 1e-6, (mins.min(), int(mins.argmin()))
    bound = a["check"]["clearance_bound"]
    assert 0.010 <= bound <= mins.min() + 1e-9
    assert a["check"]["min_clearance"] == pytest.approx(mins.min(), abs=5e-3)      # 0.1° states against 0.5°
    # and the closest approach to the cell it reports is where coal finds it
    cc = a["closest_cell"]
    got = clearances(world, cc["q"], part)
    assert got[(cc["body"], world.obstacles[cc["other"]].name)] == pytest.approx(cc["clearance"], abs=1e-5)


def test_report_holds_the_views_and_numbers(run):
    d = run.results
    assert_report_holds(run.report, d, texts=["self_collision_3d", "windows_only_3d", "cell_aware_3d",
                                              "studies/cells/fanuc_weld_cell.toml", "weld_part.stl"],
                        pngs=["j2_j3_map.png", "seam.png", "clearance.png"])
    page = run.report.read_text(encoding="utf-8")
    assert page.count('class="plot3d"') == 3
    assert "part (mesh: 512 triangles)" in page                 # the original mesh, not its spheres


def test_report_renders_in_a_browser(run, report_browser):
    d = run.results
    deep = d["move"]["windows_only"]["deepest"]
    assert_report_renders(report_browser, run.report, d,
                          numbers=(f"{1000 * -deep['clearance']:.4g} mm deep", "The windows-only plan",
                                   "The cell-aware plan", f"{d['cell']['design_task']['targets']} targets"))
