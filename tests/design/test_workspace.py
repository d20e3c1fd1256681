"""design.workspace and studies.plots.plot_workspace against independent values.

Expected numbers come from closed forms written here in numpy (planar 2R and SCARA kinematics,
their Jacobians, the reachable set of a 2R arm with joint limits by closed-form inverse kinematics on
a fine Cartesian grid) and from docs/machines.md (SCARA: maximal reach 675 mm at θ2 = 0), never from the
code's own earlier output.  The robot numbers are read from the bundled TOML files with ``tomllib``.
"""
from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest

import kin
from design.workspace import (
    DEFAULT_RELATIVE_THRESHOLD,
    DEFAULT_VOXELS_ALONG_LONGEST,
    Workspace,
    WorkspaceError,
    compute_workspace,
    sample_joint_space,
)
from kin.errors import RmtError
from kin.robotfile import ROBOT_DIR

MM = 1e-3


def robot_file(name: str) -> dict:
    with open(ROBOT_DIR / f"{name}.toml", "rb") as fh:
        return tomllib.load(fh)


@pytest.fixture(scope="module")
def planar():
    return kin.load_robot("planar_2r")


@pytest.fixture(scope="module")
def scara():
    return kin.load_robot("scara_rrp")


@pytest.fixture(scope="module")
def fanuc():
    return kin.load_robot("fanuc_m16ib20")


# ---- independent references ----------------------------------------------------------------------
def reachable_area_2r(a1: float, a2: float, lim1, lim2, h: float) -> float:
    """Area (m²) of the set reachable by a planar 2R arm with joint limits, by closed-form IK.

    Midpoints of an h-grid over the disc of radius a1 + a2; a point is reachable when one of its two
    elbow solutions θ2 = ±acos((r² − a1² − a2²)/(2 a1 a2)) lies in lim2 and the matching
    θ1 = atan2(y, x) − atan2(a2 sin θ2, a1 + a2 cos θ2) (mod 2π) lies in lim1.
    """
    R = a1 + a2
    g = np.arange(-R + h / 2, R, h)
    X, Y = np.meshgrid(g, g, indexing="ij")
    c = (X ** 2 + Y ** 2 - a1 ** 2 - a2 ** 2) / (2 * a1 * a2)
    inside = np.abs(c) <= 1.0
    c = np.clip(c, -1.0, 1.0)
    phi = np.arctan2(Y, X)
    ok = np.zeros(X.shape, dtype=bool)
    for sign in (1.0, -1.0):
        t2 = sign * np.arccos(c)
        in2 = (t2 >= lim2[0]) & (t2 <= lim2[1])
        t1 = phi - np.arctan2(a2 * np.sin(t2), a1 + a2 * np.cos(t2))
        in1 = np.zeros_like(ok)
        for k in (-1, 0, 1):
            in1 |= (t1 + 2 * math.pi * k >= lim1[0]) & (t1 + 2 * math.pi * k <= lim1[1])
        ok |= inside & in1 & in2
    return float(ok.sum()) * h * h


def scara_fk_jv(Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """SCARA of docs/machines.md §2 in closed form (SI): positions (N, 3) and position Jacobians (N, 3, 3)."""
    t1, t2, d3 = Q[:, 0], Q[:, 1], Q[:, 2]
    a = 0.225
    c1, s1, c12, s12 = np.cos(t1), np.sin(t1), np.cos(t1 + t2), np.sin(t1 + t2)
    p = np.stack([a * c1 + 2 * a * c12, a * s1 + 2 * a * s12, 2 * MM + d3], axis=1)  # links a2 + a3 in line
    J = np.zeros((len(Q), 3, 3))
    J[:, 0, 0], J[:, 0, 1] = -a * s1 - 2 * a * s12, -2 * a * s12
    J[:, 1, 0], J[:, 1, 1] = a * c1 + 2 * a * c12, 2 * a * c12
    J[:, 2, 2] = 1.0
    return p, J


def test_scara_closed_form_matches_robots_md():
    # the reference values of docs/machines.md §2 validate the closed form used below
    p, J = scara_fk_jv(np.array([[0.0, 0.0, -197 * MM], [0.5, 1.0, -150 * MM]]))
    assert np.allclose(p / MM, [[675, 0, -195], [229.29, 556.74, -148]], atol=0.005)
    assert np.linalg.det(J[1, :2, :2]) / MM ** 2 == pytest.approx(101250 * math.sin(1.0), rel=1e-12)


# ---- area and volume -----------------------------------------------------------------------------
def test_planar_2r_area_converges_to_the_reachable_annulus(planar):
    doc = robot_file("planar_2r")
    a1, a2 = (j["a"] for j in doc["joints"])
    lim1, lim2 = (tuple(j["limits"]) for j in doc["joints"])
    assert doc["length_unit"] == "m" and doc["angle_unit"] == "rad"
    exact = reachable_area_2r(a1, a2, lim1, lim2, h=0.004)
    if all(lim[0] <= -math.pi + 1e-12 and lim[1] >= math.pi - 1e-12 for lim in (lim1, lim2)):
        # full turns: the reachable set is the annulus (a1 − a2) ≤ r ≤ (a1 + a2)
        annulus = math.pi * ((a1 + a2) ** 2 - (a1 - a2) ** 2)
        assert exact == pytest.approx(annulus, rel=5e-3)
        exact = annulus
    errors = []
    for voxel in (0.04, 0.02, 0.01):   # pixel sides in m; boundary bias ≈ perimeter · voxel / 2
        ws = compute_workspace(planar, 1_000_000, "sobol", seed=0, voxel=voxel)
        assert ws.dimension == 2 and ws.degenerate_axes == ("z",)
        assert ws.volume == 0.0 and ws.voxel == voxel
        errors.append(abs(ws.area / exact - 1.0))
    assert errors[0] > errors[1] > errors[2], errors      # converges as the pixel shrinks
    assert errors[2] < 0.03, errors                        # within 3 % at 10 mm pixels, 10⁶ samples
    assert ws.n_samples == 1_000_000
    assert ws.reach == pytest.approx(a1 + a2, abs=1e-6)


def test_planar_default_pixel_is_stated(planar):
    ws = compute_workspace(planar, 20_000, "random", seed=1)
    extent = ws.bbox_max - ws.bbox_min
    assert extent[2] < 1e-9
    assert ws.voxel == pytest.approx(extent.max() / DEFAULT_VOXELS_ALONG_LONGEST, rel=1e-12)
    assert str(DEFAULT_VOXELS_ALONG_LONGEST) in ws.voxel_rule
    assert ws.area == pytest.approx(ws.occupied * ws.voxel ** 2)
    d = ws.to_dict()
    assert d["voxel"]["size"] == ws.voxel and d["area"] == ws.area and d["volume"] == 0.0


def test_scara_volume_against_closed_form_reachable_set(scara):
    doc = robot_file("scara_rrp")
    assert doc["length_unit"] == "mm"
    lim1, lim2, lim3 = (tuple(j["limits"]) for j in doc["joints"])
    # x–y region of a 2R arm with a1 = 225 mm and a2 + a3 = 450 mm in line, swept over the stroke of d3
    area = reachable_area_2r(0.225, 0.45, lim1, lim2, h=0.002)
    exact = area * (lim3[1] - lim3[0]) * MM
    # 10 mm voxels divide the 200 mm stroke exactly: no partial layer in z
    ws = compute_workspace(scara, 1_000_000, "sobol", seed=0, voxel=0.01)
    assert ws.dimension == 3 and ws.area is None
    assert ws.volume == pytest.approx(ws.occupied * 0.01 ** 3)
    assert ws.volume == pytest.approx(exact, rel=0.03)
    assert ws.functional_volume <= ws.volume


def test_scara_reach_675_mm(scara):
    ws = compute_workspace(scara, 100_000, "sobol", seed=0)
    # docs/machines.md §2: maximal reach 675 mm from the base axis, at θ2 = 0
    assert ws.radial_reach / MM == pytest.approx(675.0, abs=0.05)
    assert ws.radial_reach / MM <= 675.0 + 1e-9
    # from the base origin: the stretched arm at the bottom of the stroke, z = 2 − 297 mm
    assert ws.reach / MM == pytest.approx(math.hypot(675.0, 295.0), abs=1.0)
    assert ws.reach / MM <= math.hypot(675.0, 295.0) + 1e-9


# ---- positions and dexterity ---------------------------------------------------------------------
def test_scara_positions_and_sigma_min_match_closed_form(scara):
    N, seed = 50_000, 7
    ws = compute_workspace(scara, N, "random", seed=seed)
    Q = np.random.default_rng(seed).uniform(scara.chain.lower, scara.chain.upper, size=(N, 3))
    assert np.allclose(sample_joint_space(scara, N, "random", seed), Q, rtol=0, atol=1e-15)
    p, J = scara_fk_jv(Q)
    assert np.allclose(ws.positions, p, rtol=0, atol=1e-12)
    sigma = np.linalg.svd(J, compute_uv=False)[:, -1]
    assert np.allclose(ws.measure, sigma, rtol=1e-9, atol=1e-12)
    threshold = DEFAULT_RELATIVE_THRESHOLD * np.median(sigma)
    assert ws.threshold == pytest.approx(threshold, rel=1e-9)
    assert np.array_equal(ws.near_singular, sigma < threshold)
    assert ws.n_near_singular == int(np.sum(sigma < threshold)) > 0
    # near-singular SCARA poses are the stretched arm: |sin θ2| small
    assert np.all(np.abs(np.sin(Q[ws.near_singular, 1])) < 0.2)


def test_near_singular_samples_have_small_sigma_min(fanuc):
    ws = compute_workspace(fanuc, 20_000, "sobol", seed=3)
    Q = sample_joint_space(fanuc, 20_000, "sobol", seed=3)
    rng = np.random.default_rng(0)
    near = np.flatnonzero(ws.near_singular)
    fine = np.flatnonzero(~ws.near_singular)
    assert len(near) > 0 and len(fine) > 0
    pick_near = rng.choice(near, min(300, len(near)), replace=False)
    pick_fine = rng.choice(fine, 300, replace=False)
    assert np.all(fanuc.sigma_min(Q[pick_near]) < ws.threshold)
    assert np.all(fanuc.sigma_min(Q[pick_fine]) >= ws.threshold)
    assert np.allclose(fanuc.fk(Q[pick_fine])[:, :3, 3], ws.positions[pick_fine], atol=1e-12)


def test_absolute_threshold_and_other_measures(scara):
    ws = compute_workspace(scara, 10_000, "random", seed=2, measure="manipulability", threshold=0.01)
    Q = sample_joint_space(scara, 10_000, "random", seed=2)
    _, J = scara_fk_jv(Q)
    w = np.abs(np.linalg.det(J))
    assert np.allclose(ws.measure, w, rtol=1e-9, atol=1e-14)
    assert ws.threshold == 0.01 and np.array_equal(ws.near_singular, w < 0.01)
    inv = compute_workspace(scara, 10_000, "random", seed=2, measure="inverse_condition")
    s = np.linalg.svd(J, compute_uv=False)
    assert np.allclose(inv.measure, s[:, -1] / s[:, 0], rtol=1e-9, atol=1e-14)


# ---- sampling ------------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["sobol", "random"])
def test_same_seed_same_result_different_seed_differs(scara, method):
    a = compute_workspace(scara, 5_000, method, seed=11)
    b = compute_workspace(scara, 5_000, method, seed=11)
    c = compute_workspace(scara, 5_000, method, seed=12)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.measure, b.measure)
    da, db = a.to_dict(), b.to_dict()
    da.pop("elapsed_s"), db.pop("elapsed_s")
    assert da == db
    assert not np.array_equal(a.positions, c.positions)
    Q = sample_joint_space(scara, 5_000, method, seed=11)
    assert Q.shape == (5_000, 3)
    assert np.all(Q >= scara.chain.lower) and np.all(Q <= scara.chain.upper)


def test_sobol_covers_each_joint_evenly(fanuc):
    Q = sample_joint_space(fanuc, 4096, "sobol", seed=0)
    U = (Q - fanuc.chain.lower) / (fanuc.chain.upper - fanuc.chain.lower)
    for k in range(fanuc.n):   # a scrambled Sobol set of 2^12 points: 256 points in each 1/16 bin
        assert np.array_equal(np.bincount((U[:, k] * 16).astype(int), minlength=16), np.full(16, 256))


@pytest.mark.parametrize("name,n_samples,k", [("scara_rrp", 1000, 10), ("scara_rrp", 1001, 11),
                                              ("fanuc_m16ib20", 1000, 4), ("planar_2r", 50, 8)])
def test_grid_counts_and_endpoints(name, n_samples, k):
    robot = kin.load_robot(name)
    n = robot.n
    assert k ** n >= n_samples > (k - 1) ** n          # k = ⌈n_samples^(1/n)⌉, by integer arithmetic
    Q = sample_joint_space(robot, n_samples, "grid")
    assert Q.shape == (k ** n, n)
    assert len(np.unique(Q, axis=0)) == k ** n
    for j in range(n):
        values = np.unique(Q[:, j])
        assert len(values) == k
        assert values[0] == robot.chain.lower[j] and values[-1] == robot.chain.upper[j]
    if name == "scara_rrp":
        ws = compute_workspace(robot, n_samples, "grid")
        assert ws.n_samples == k ** n and ws.n_requested == n_samples and ws.points_per_joint == k


# ---- errors --------------------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs,words", [
    ({"n_samples": 0}, ["n_samples", ">= 1"]),
    ({"n_samples": -5}, ["n_samples", ">= 1"]),
    ({"n_samples": 2.5}, ["n_samples", "integer"]),
    ({"n_samples": "many"}, ["n_samples", "integer"]),
    ({"method": "halton"}, ["method", "'halton'", "'sobol'", "'random'", "'grid'"]),
    ({"voxel": -0.01}, ["voxel", "> 0"]),
    ({"voxel": 0.0}, ["voxel", "> 0"]),
    ({"voxel": float("nan")}, ["voxel", "> 0"]),
    ({"measure": "dexterity"}, ["measure", "'sigma_min'", "'manipulability'", "'inverse_condition'"]),
    ({"threshold": -1.0}, ["threshold", "> 0"]),
    ({"seed": -1}, ["seed", "non-negative"]),
])
def test_bad_inputs_name_the_parameter(scara, kwargs, words):
    args = {"n_samples": 100} | kwargs
    with pytest.raises(WorkspaceError) as err:
        compute_workspace(scara, **args)
    assert isinstance(err.value, RmtError) and isinstance(err.value, ValueError)
    for w in words:
        assert w in str(err.value), (w, str(err.value))


def test_sample_joint_space_rejects_bad_inputs(scara):
    with pytest.raises(WorkspaceError, match="n_samples"):
        sample_joint_space(scara, 0)
    with pytest.raises(WorkspaceError, match="allowed: 'sobol', 'random', 'grid'"):
        sample_joint_space(scara, 10, "lhs")


def test_to_dict_is_a_json_summary(scara):
    ws = compute_workspace(scara, 30_000)
    assert isinstance(ws, Workspace)
    text = json.dumps(ws.to_dict())
    assert len(text) < 4000                               # a summary: no per-sample arrays
    d = json.loads(text)
    assert d["counts"]["samples"] == 30_000
    assert d["counts"]["near_singular"] + d["counts"]["dexterous"] == 30_000
    assert d["volume"] == pytest.approx(d["voxel"]["occupied"] * d["voxel"]["size"] ** 3)
    assert d["units"]["length"] == "m" and d["units"]["file_length_unit"] == "mm"


# ---- plot ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["scara_rrp", "fanuc_m16ib20"])
def test_plot_workspace_writes_png(tmp_path, name):
    from studies.plots import plot_workspace
    ws = compute_workspace(name, 30_000, seed=0)
    out = tmp_path / "sub" / f"{name}.png"
    path = plot_workspace(ws, out, title=f"{name} workspace")
    assert path == out and out.is_file()
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > 10_000
    assert [p.name for p in out.parent.iterdir()] == [out.name]   # no temporary file left behind


def test_volume_convergence_is_reported():
    # the planar 2R annulus (r from |l1 − l2| to l1 + l2): with few samples most pixels are empty
    # and the area is a lower bound; with many it converges to the closed form
    robot = kin.load_robot("planar_2r")
    few = compute_workspace(robot, n_samples=2000, seed=0)
    many = compute_workspace(robot, n_samples=400_000, seed=0)
    assert not few.converged and few.half_ratio < 0.95
    assert many.converged and many.to_dict()["voxel"]["converged"] is True
    assert few.area < many.area
    # the half count is the count of every other sample, recomputed here
    from design.workspace import voxel_occupancy
    axes = tuple(i for i in range(3) if "xyz"[i] not in few.degenerate_axes)
    assert few.occupied_half == voxel_occupancy(few.positions[::2], few.voxel, few.bbox_min, axes).size
