"""Tool paths (``planning.toolpath``), their validation (``planning.toolpath.check``), the plot and
``rmt validate-toolpath``.

Numbers are checked against independent values: rotations from scipy's ``Rotation``, arc and line
geometry in closed form, poses from the numpy DH re-implementation ``dh_numpy.fk_numpy``, expected
problem indices from the joint path a Cartesian path was made from, joint speeds from finite
differences computed here, and docs/machines.md §6 for the UR3-like arm with its pen.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kin
from planning.toolpath import ToolPath, ToolPathError, load_toolpath, read_toolpath_csv, read_toolpath_toml
from planning.toolpath.check import KINDS, validate_toolpath
from planning.windows import build_windows
from studies.cli import main
from tests.dh_numpy import fk_numpy, jacobian_numpy

ROOT = Path(__file__).resolve().parents[3]
DRAWING = ROOT / "studies" / "toolpaths" / "ur3_drawing.toml"
SCARA_CSV = ROOT / "studies" / "toolpaths" / "scara_line.csv"
PEN_Q = np.array([0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0, 0.0])
PEN_P = np.array([-0.2173, -0.3878, 1.03611])          # docs/machines.md §6, pen tip at PEN_Q


@pytest.fixture(scope="module")
def fanuc():
    return kin.load_robot("fanuc_m16ib20")


@pytest.fixture(scope="module")
def fanuc_windows(fanuc):
    return build_windows(fanuc, margin=0.05)


@pytest.fixture(scope="module")
def pen():
    return kin.load_robot("ur3_homework_pen")


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def fanuc_joint_path(M: int = 200) -> np.ndarray:
    """A smooth FANUC joint path whose q5 goes from -0.3 to 0.3 rad (through the wrist singularity),
    far from the elbow and shoulder singularities; q5 is never exactly 0 (M even)."""
    u = np.linspace(0.0, 1.0, M)
    return np.stack([0.2 + 0.3 * u, 0.1 + 0.2 * u, -0.3 + 0.1 * u, 0.4 - 0.6 * u, -0.3 + 0.6 * u, 0.1 + 0.5 * u], 1)


# ============================================================================ robot file: the pen
class TestPenRobot:
    def test_pen_tip_matches_robots_md(self, pen):
        chain = kin.load_chain("ur3_homework_pen")
        assert chain.angle_unit == "rad" and chain.length_unit == "m"
        np.testing.assert_allclose(fk_numpy(chain, PEN_Q)[:3, 3], PEN_P, atol=5e-6)
        np.testing.assert_allclose(pen.fk(PEN_Q)[:3, 3], PEN_P, atol=5e-6)
        assert abs(np.linalg.det(jacobian_numpy(chain, PEN_Q))) < 1e-12     # singular: θ5 = 0

    def test_same_as_flange_robot_but_d6(self):
        flange, pen_c = kin.load_chain("ur3_homework"), kin.load_chain("ur3_homework_pen")
        a, b = flange.dh_table(), pen_c.dh_table()
        np.testing.assert_array_equal(a[:5], b[:5])
        np.testing.assert_array_equal(np.delete(a[5], 2), np.delete(b[5], 2))
        assert (a[5, 2], b[5, 2]) == (0.0768, 0.1218)
        np.testing.assert_array_equal(flange.limits, pen_c.limits)


# ================================================================================== CSV reader
class TestCsv:
    def test_rpy_in_file_units(self, tmp_path):
        # puma560 is mm / deg: values convert once, to m / rad
        p = write(tmp_path, "a.csv", "# comment\nx, y, z, roll, pitch, yaw\n100, 200, 300, 10, 20, 30\n"
                                     "110, 200, 300, -40, 50, 170\n")
        tp = read_toolpath_csv(p, kin.load_robot("puma560"))
        assert len(tp) == 2 and tp.has_orientation and tp.t is None and tp.feed is None
        np.testing.assert_allclose(tp.positions, [[0.1, 0.2, 0.3], [0.11, 0.2, 0.3]], atol=1e-15)
        for k, rpy in enumerate([(10, 20, 30), (-40, 50, 170)]):
            # fixed-axis x-y-z (roll about x, then pitch about y, then yaw about z): R = Rz·Ry·Rx
            R = Rotation.from_euler("xyz", rpy, degrees=True).as_matrix()
            np.testing.assert_allclose(tp.poses[k, :3, :3], R, atol=1e-14)
            np.testing.assert_array_equal(tp.poses[k, 3], [0, 0, 0, 1])
        np.testing.assert_allclose(tp.s, [0.0, 0.01], atol=1e-15)
        np.testing.assert_array_equal(tp.line, [3, 4])

    def test_quaternion_and_feed(self, tmp_path):
        quats = Rotation.from_euler("zyx", [[10, 20, 30], [40, -50, 60], [0, 0, 0]], degrees=True).as_quat()  # x y z w
        rows = ["qx;qy;qz;qw;x;y;z;feed"]
        P = np.array([[0.5, 0.0, 1.0], [0.5, 0.3, 1.0], [0.5, 0.3, 0.6]])
        for q, p in zip(quats, P):
            rows.append(";".join(str(v) for v in (*q, *p, 0.1)))
        tp = read_toolpath_csv(write(tmp_path, "q.csv", "\n".join(rows) + "\n"), kin.load_robot("fanuc_m16ib20"))
        np.testing.assert_allclose(tp.poses[:, :3, :3], Rotation.from_quat(quats).as_matrix(), atol=1e-14)
        np.testing.assert_allclose(tp.positions, P)
        np.testing.assert_allclose(tp.s, [0.0, 0.3, 0.7], atol=1e-15)
        np.testing.assert_allclose(tp.t, [0.0, 3.0, 7.0], atol=1e-12)        # s / 0.1 m/s
        np.testing.assert_allclose(tp.feed, 0.1)

    def test_times_and_position_only_whitespace(self, tmp_path):
        tp = read_toolpath_csv(write(tmp_path, "t.csv", "t x y z\n5 400 0 -150\n6 400 100 -150\n8 300 100 -150\n"),
                               kin.load_robot("scara_rrp"))
        assert not tp.has_orientation
        np.testing.assert_allclose(tp.t, [0.0, 1.0, 3.0])
        np.testing.assert_allclose(tp.s, [0.0, 0.1, 0.2], atol=1e-15)
        np.testing.assert_allclose(tp.poses[:, :3, :3], np.broadcast_to(np.eye(3), (3, 3, 3)))

    def test_bundled_scara_example(self):
        tp = load_toolpath(SCARA_CSV, kin.load_robot("scara_rrp"))
        assert len(tp) == 21 and not tp.has_orientation
        a, b = np.array([0.3, 0.3, -0.15]), np.array([0.45, -0.15, -0.15])
        np.testing.assert_allclose(tp.positions[0], a, atol=1e-12)
        np.testing.assert_allclose(tp.positions[-1], b, atol=1e-12)
        np.testing.assert_allclose(tp.t[-1], np.linalg.norm(b - a) / 0.05, rtol=1e-9)

    @pytest.mark.parametrize("text, field, words", [
        ("x,y,roll,pitch,yaw\n1,2,3,4,5\n", "line 1 (header)", ["missing column", "z", "required: x, y, z"]),
        ("1,2,3\n4,5,6\n", "line 1 (header)", ["header", "allowed: x, y, z"]),
        ("x,y,z,colour\n1,2,3,4\n", "line 1 (header)", ["unknown column 'colour'", "allowed:"]),
        ("x,y,z,roll,pitch\n1,2,3,4,5\n", "line 1 (header)", ["yaw", "roll, pitch, yaw"]),
        ("x,y,z,roll,pitch,yaw,qw,qx,qy,qz\n" + ",".join(["0"] * 10) + "\n", "line 1 (header)", ["not both"]),
        ("x,y,z\n1,2,3\n1,two,3\n", "line 3, column 'y'", ["'two' is not a number"]),
        ("x,y,z\n1,2,3\n1,nan,3\n", "line 3, column 'y'", ["NaN"]),
        ("x,y,z\n1,2,3\n1,inf,3\n", "line 3, column 'y'", ["finite"]),
        ("x,y,z\n1,2,3\n1,2\n", "line 3", ["2 values", "3 columns"]),
        ("x,y,z,feed\n1,2,3,10\n1,2,4,0\n", "line 3, column 'feed'", ["outside the allowed range"]),
        ("x,y,z,feed\n1,2,3,-5\n", "line 2, column 'feed'", ["outside the allowed range"]),
        ("x,y,z,t\n1,2,3,0\n1,2,4,0\n", "line 3, column 't'", ["strictly increasing"]),
        ("x,y,z,qw,qx,qy,qz\n1,2,3,2,0,0,0\n", "line 2, columns qw..qz", ["unit quaternion"]),
        ("x,y,z\n", None, ["no waypoints"]),
        ("", None, ["header is required"]),
    ])
    def test_bad_input_names_file_and_field(self, tmp_path, text, field, words):
        p = write(tmp_path, "bad.csv", text)
        with pytest.raises(ToolPathError) as ei:
            read_toolpath_csv(p, kin.load_robot("fanuc_m16ib20"))
        msg = str(ei.value)
        assert isinstance(ei.value, kin.RmtError)
        assert msg.startswith(str(p)), msg
        if field:
            assert f"{p}: {field}:" in msg, msg
        for w in words:
            assert w in msg, msg

    def test_missing_file_and_unknown_extension(self, tmp_path):
        with pytest.raises(ToolPathError, match="no such tool-path file"):
            load_toolpath(tmp_path / "none.csv", kin.load_robot("fanuc_m16ib20"))
        with pytest.raises(ToolPathError, match=r"unknown tool-path file type '\.txt'; allowed: \.csv, \.toml"):
            load_toolpath(write(tmp_path, "a.txt", "x,y,z\n"), kin.load_robot("fanuc_m16ib20"))


# ================================================================================= TOML reader
ARC_LINE = """
length_unit = "mm"
angle_unit = "deg"
[start]
xyz = [100.0, 0.0, 50.0]
rpy = [180.0, 0.0, 0.0]
[[segments]]
type = "arc"
center = [0.0, 0.0, 50.0]
normal = [0.0, 0.0, 1.0]
to = [0.0, 100.0, 50.0]
feed = 20.0
points = 90
[[segments]]
type = "line"
to = [0.0, 100.0, 0.0]
feed = 10.0
step = 1.0
[[segments]]
type = "arc"
through = [0.0, 130.0, 30.0]
to = [0.0, 160.0, 0.0]
duration = 2.0
points = 50
rpy = [180.0, 0.0, 90.0]
"""


class TestToml:
    def test_arc_line_geometry(self, tmp_path):
        tp = read_toolpath_toml(write(tmp_path, "p.toml", ARC_LINE), kin.load_robot("fanuc_m16ib20"))
        P = tp.positions
        assert len(tp) == 1 + 90 + 50 + 50
        seg = tp.segment
        assert seg[0] == -1 and (seg == 0).sum() == 90 and (seg == 1).sum() == 50 and (seg == 2).sum() == 50
        # arc 1: quarter circle of radius 0.1 m about the z axis at z = 0.05, counter-clockwise about +z
        A = P[seg <= 0]
        np.testing.assert_allclose(np.linalg.norm(A[:, :2], axis=1), 0.1, atol=1e-15)
        np.testing.assert_allclose(A[:, 2], 0.05, atol=1e-15)
        ang = np.arctan2(A[:, 1], A[:, 0])
        np.testing.assert_allclose(ang, np.linspace(0, math.pi / 2, 91), atol=1e-12)
        # line: collinear, evenly spaced 1 mm, from the arc's end straight down
        L = P[(seg == 1) | (np.arange(len(P)) == 90)]
        np.testing.assert_allclose(L[:, :2], np.broadcast_to([0.0, 0.1], (51, 2)), atol=1e-15)
        np.testing.assert_allclose(L[:, 2], np.linspace(0.05, 0.0, 51), atol=1e-15)
        # arc 2 through three points: centre (0, 0.13, 0) radius 0.03 (all three at that distance)
        B = P[(seg == 2) | (np.arange(len(P)) == 140)]
        np.testing.assert_allclose(np.linalg.norm(B - [0.0, 0.13, 0.0], axis=1), 0.03, atol=1e-14)
        np.testing.assert_allclose(B[:, 0], 0.0, atol=1e-15)
        assert B[25, 2] > 0.029    # half-way it passes the `through` point's side (z > 0)
        # arc length: π/2·0.1 + 0.05 + π·0.03, and s matches the chord sum of the dense points
        total = math.pi / 2 * 0.1 + 0.05 + math.pi * 0.03
        np.testing.assert_allclose(tp.s[-1], total, rtol=1e-12)
        chords = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
        np.testing.assert_allclose(tp.s, chords, atol=2e-5)
        # timing: segment durations s/feed (feeds in mm/s) and the given 2 s
        t_seg = [tp.t[90], tp.t[140] - tp.t[90], tp.t[-1] - tp.t[140]]
        np.testing.assert_allclose(t_seg, [math.pi / 2 * 100 / 20, 50 / 10, 2.0], rtol=1e-12)
        # orientation: held on the first two segments, slerped to the last segment's rpy
        R0 = Rotation.from_euler("xyz", [180, 0, 0], degrees=True).as_matrix()
        R1 = Rotation.from_euler("xyz", [180, 0, 90], degrees=True).as_matrix()
        np.testing.assert_allclose(tp.poses[:141, :3, :3], np.broadcast_to(R0, (141, 3, 3)), atol=1e-15)
        np.testing.assert_allclose(tp.poses[-1, :3, :3], R1, atol=1e-12)
        mid = Rotation.from_matrix(R0.T @ tp.poses[140 + 25, :3, :3]).magnitude()
        np.testing.assert_allclose(mid, math.pi / 4, atol=1e-12)

    def test_full_circle(self, tmp_path):
        text = """
[start]
xyz = [1.0, 0.0, 1.0]
[[segments]]
type = "arc"
center = [0.8, 0.0, 1.0]
normal = [0.0, 1.0, 0.0]
to = [1.0, 0.0, 1.0]
feed = 0.1
points = 400
"""
        tp = read_toolpath_toml(write(tmp_path, "c.toml", text), kin.load_robot("fanuc_m16ib20"))
        assert not tp.has_orientation
        np.testing.assert_allclose(tp.s[-1], 2 * math.pi * 0.2, rtol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(tp.positions - [0.8, 0.0, 1.0], axis=1), 0.2, atol=1e-15)
        np.testing.assert_allclose(tp.positions[-1], tp.positions[0], atol=1e-15)
        # about +y: from +x towards -z
        assert tp.positions[100, 2] < 1.0 - 0.19

    def test_bundled_ur3_drawing(self, pen):
        tp = load_toolpath(DRAWING, pen)
        R = 0.05
        assert len(tp) == 5001
        P = tp.positions
        np.testing.assert_allclose(P[:, 0], -0.2173, atol=1e-15)                       # the y-z plane
        np.testing.assert_allclose(P[0], PEN_P, atol=1e-15)
        np.testing.assert_allclose(P[-1], PEN_P, atol=1e-12)                           # closed
        c = PEN_P - [0, 0, R]
        corners = [c + [0, -R, 0], c + [0, -R, -0.05], c + [0, R, -0.05], c + [0, R, 0]]
        np.testing.assert_allclose(P[[1000, 2000, 3000, 4000]], corners, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(P[:1001] - c, axis=1), R, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(P[4000:] - c, axis=1), R, atol=1e-12)
        # counter-clockwise seen from +x: (y, z) turns positively
        d = P[1:1001, 1:] - c[1:]
        ang = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
        assert np.all(np.diff(ang) > 0)
        np.testing.assert_allclose(tp.s[-1], math.pi * R + 0.2, rtol=1e-12)
        np.testing.assert_allclose(tp.t[[1000, 2000, 3000, 4000, 5000]], [4, 8, 12, 16, 20], rtol=1e-12)
        # the orientation is held at the pen pose's (docs/machines.md §6: R at q = 0 is the same matrix)
        Rpen = np.array([[0, 0, -1], [-1, 0, 0], [0, 1, 0]], float)
        np.testing.assert_allclose(tp.poses[:, :3, :3], np.broadcast_to(Rpen, (5001, 3, 3)), atol=1e-15)

    BASE = """
[start]
xyz = [1.0, 0.0, 1.0]
rpy = [0.0, 0.0, 0.0]
[[segments]]
"""

    @pytest.mark.parametrize("segment, field, words", [
        ('type = "spline"\nto = [1, 1, 1]\nfeed = 1\npoints = 2', "segments[0].type",
         ["unknown segment type 'spline'", "allowed: line, arc"]),
        ('to = [1, 1, 1]\nfeed = 1\npoints = 2', "segments[0].type", ["missing field", "allowed: line, arc"]),
        ('type = "line"\nto = [1.0, 0.0, 1.0]\nfeed = 1\npoints = 2', "segments[0].to", ["zero-length"]),
        ('type = "line"\nto = [1, 1, 1]\nfeed = 0\npoints = 2', "segments[0].feed", ["> 0"]),
        ('type = "line"\nto = [1, 1, 1]\nfeed = -2.5\npoints = 2', "segments[0].feed", ["> 0"]),
        ('type = "line"\nto = [1, 1, 1]\npoints = 2', "segments[0].feed", ["missing field"]),
        ('type = "line"\nto = [1, nan, 1]\nfeed = 1\npoints = 2', "segments[0].to[1]", ["finite"]),
        ('type = "line"\nto = [1, 1]\nfeed = 1\npoints = 2', "segments[0].to", ["list of 3 numbers"]),
        ('type = "line"\nto = [1, 1, 1]\nfeed = 1', "segments[0]", ["points or step"]),
        ('type = "line"\nto = [1, 1, 1]\nfeed = 1\npoints = 0', "segments[0].points", ["integer ≥ 1"]),
        ('type = "line"\nto = [1, 1, 1]\nfeed = 1\npoints = 2\ncenter = [0, 0, 0]', "segments[0].center",
         ["unknown field", "allowed:"]),
        ('type = "arc"\ncenter = [0.8, 0, 1]\nnormal = [0, 1, 0]\nto = [0.8, 0, 1.3]\nfeed = 1\npoints = 9',
         "segments[0].to", ["from the center", "radius 0.2"]),
        ('type = "arc"\ncenter = [1.0, 0, 1]\nnormal = [0, 1, 0]\nto = [1, 0, 1]\nfeed = 1\npoints = 9',
         "segments[0].center", ["zero-length", "radius 0"]),
        ('type = "arc"\ncenter = [0.8, 0, 1]\nto = [0.8, 0, 1.2]\nfeed = 1\npoints = 9', "segments[0].normal",
         ["missing field"]),
        ('type = "arc"\nthrough = [1.1, 0, 1]\nto = [1.2, 0, 1]\nfeed = 1\npoints = 9', "segments[0].through",
         ["collinear"]),
    ])
    def test_bad_input_names_file_and_field(self, tmp_path, segment, field, words):
        p = write(tmp_path, "bad.toml", self.BASE + segment + "\n")
        with pytest.raises(ToolPathError) as ei:
            read_toolpath_toml(p, kin.load_robot("fanuc_m16ib20"))
        msg = str(ei.value)
        assert msg.startswith(f"{p}: {field}:"), msg
        for w in words:
            assert w in msg, msg

    @pytest.mark.parametrize("text, field, words", [
        ('[[segments]]\ntype = "line"\nto = [1, 1, 1]\nfeed = 1\npoints = 2\n', "start", ["missing table"]),
        ('length_unit = "furlong"\n[start]\nxyz = [0, 0, 0]\n', "length_unit", ["allowed: m, mm, in"]),
        ('[start]\nxyz = [0, 0, 0]\n', "segments", ["at least one"]),
        ('colour = 1\n', "colour", ["unknown field", "allowed:"]),
        ('[start\n', None, ["not valid TOML"]),
    ])
    def test_bad_file_level_input(self, tmp_path, text, field, words):
        p = write(tmp_path, "bad.toml", text)
        with pytest.raises(ToolPathError) as ei:
            read_toolpath_toml(p, kin.load_robot("fanuc_m16ib20"))
        msg = str(ei.value)
        assert msg.startswith(f"{p}: {field}:" if field else f"{p}:"), msg
        for w in words:
            assert w in msg, msg


# =================================================================================== validator
class TestValidate:
    def test_window_crossing_flagged_at_the_right_waypoint(self, fanuc, fanuc_windows):
        Qj = fanuc_joint_path()
        tp = ToolPath.from_poses(fanuc.fk(Qj), feed=0.05)
        rep = validate_toolpath(fanuc, tp, windows=fanuc_windows, start_q=Qj[0])
        expected = int(np.argmax(np.abs(Qj[:, 4]) <= 0.05))          # from the joint path, not the windows code
        assert expected > 0
        assert not rep.ok
        p = rep.first_problem
        assert (p.index, p.kind) == (expected, "window")
        assert rep.window_name(expected).startswith("wrist") and rep.window_name(expected - 1) is None
        np.testing.assert_array_equal(rep.window >= 0, np.abs(Qj[:, 4]) <= 0.05)
        assert p.s == pytest.approx(tp.s[expected]) and p.t == pytest.approx(tp.t[expected])
        assert rep.counts["window"] == int((np.abs(Qj[:, 4]) <= 0.05).sum())
        assert rep.reachable.all() and rep.counts["unreachable"] == 0 and rep.counts["branch_jump"] == 0
        assert f"waypoint {expected} of 200" in rep.verdict() and "window" in rep.verdict()

    def test_solutions_reproduce_the_poses(self, fanuc):
        Qj = fanuc_joint_path()
        poses = fanuc.fk(Qj)
        rep = validate_toolpath(fanuc, ToolPath.from_poses(poses, feed=0.05), start_q=Qj[0])
        assert rep.ok and rep.mode == "pose"
        for i in range(0, len(Qj), 7):
            np.testing.assert_allclose(fk_numpy(fanuc.chain, rep.q[i]), poses[i], atol=2e-6)
        assert rep.position_error.max() < 1e-6 and rep.orientation_error.max() < 1e-6
        # the continuous solution is the joint path it was made from (one branch, no flips)
        np.testing.assert_allclose(rep.q, Qj, atol=1e-4)

    def test_joint_speeds_are_finite_differences(self, fanuc):
        Qj = fanuc_joint_path(60)
        poses = fanuc.fk(Qj)
        feed = 0.02
        rep = validate_toolpath(fanuc, ToolPath.from_poses(poses, feed=feed), start_q=Qj[0])
        t = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(poses[:, :3, 3], axis=0), axis=1))]) / feed
        np.testing.assert_allclose(rep.t, t, rtol=1e-12)
        np.testing.assert_allclose(rep.joint_speed[0], 0.0)
        np.testing.assert_allclose(rep.joint_speed[1:], np.diff(rep.q, axis=0) / np.diff(t)[:, None], rtol=1e-12)
        np.testing.assert_allclose(rep.joint_step[1:], np.abs(np.diff(rep.q, axis=0)).max(axis=1), rtol=1e-12)
        assert np.isnan(rep.speed_ratio).all()       # the FANUC file gives no joint speeds
        # with limits: ratio = max |q̇| / v_max, and "speed" where it exceeds 1
        vmax = 0.5 * np.abs(rep.joint_speed).max()
        rep2 = validate_toolpath(fanuc, ToolPath.from_poses(poses, feed=feed), start_q=Qj[0], max_speed=vmax)
        np.testing.assert_allclose(rep2.speed_ratio, np.abs(rep2.joint_speed).max(axis=1) / vmax, rtol=1e-9)
        first = int(np.argmax(rep2.speed_ratio > 1))
        assert (rep2.first_problem.index, rep2.first_problem.kind) == (first, "speed")

    def test_unreachable_waypoint(self, fanuc):
        Qj = fanuc_joint_path(80)
        poses = fanuc.fk(Qj)
        poses[50, 0, 3] += 5.0                      # 5 m further out than the arm reaches
        rep = validate_toolpath(fanuc, ToolPath.from_poses(poses, feed=0.05), start_q=Qj[0])
        p = rep.first_problem
        assert (p.index, p.kind) == (50, "unreachable")
        assert "no IK solution" in p.detail
        assert rep.counts["unreachable"] == 1 and not rep.reachable[50]
        others = np.arange(80) != 50
        assert rep.reachable[others].all()
        assert rep.problems().tolist() == [50]      # the path continues on its branch after the outlier
        np.testing.assert_allclose(rep.q[others], Qj[others], atol=1e-4)
        assert rep.position_error[50] > 3.0
        assert np.isnan(rep.joint_speed[[50, 51]]).all()

    def test_joint_limits(self, fanuc):
        Qj = fanuc_joint_path(100)
        Qj[:, 4] = np.linspace(2.0, 2.6, 100)       # q5 runs past its limit 2.44 rad
        rep = validate_toolpath(fanuc, ToolPath.from_poses(fanuc.fk(Qj), feed=0.05), start_q=Qj[0])
        first = int(np.argmax(Qj[:, 4] > 2.44))
        assert (rep.first_problem.index, rep.first_problem.kind) == (first, "limits")
        assert "joint 5" in rep.first_problem.detail
        np.testing.assert_allclose(rep.limit_margin, np.minimum(rep.q - fanuc.chain.lower,
                                                                fanuc.chain.upper - rep.q).min(axis=1))
        assert rep.counts["limits"] == int((Qj[:, 4] > 2.44).sum())

    def test_branch_jump_bound(self, fanuc):
        Qj = fanuc_joint_path(40)
        tp = ToolPath.from_poses(fanuc.fk(Qj), feed=0.05)
        step = np.abs(np.diff(Qj, axis=0)).max()
        rep = validate_toolpath(fanuc, tp, start_q=Qj[0], max_joint_step=0.5 * step)
        assert (rep.first_problem.index, rep.first_problem.kind) == (1, "branch_jump")
        assert validate_toolpath(fanuc, tp, start_q=Qj[0], max_joint_step=2 * step).ok

    def test_start_branch_is_chosen_by_start_q(self, fanuc):
        q = np.array([0.3, 0.2, -0.1, 0.5, -0.8, 0.4])
        flip = q + [0, 0, 0, -math.pi, 0, -math.pi]
        flip[4] = -q[4]                             # the wrist's other solution, same pose
        assert fanuc.within_limits(flip)
        np.testing.assert_allclose(fk_numpy(fanuc.chain, flip), fk_numpy(fanuc.chain, q), atol=1e-12)
        tp = ToolPath.from_poses(fanuc.fk(q)[None], feed=0.1)
        for start in (q, flip):
            rep = validate_toolpath(fanuc, tp, start_q=start + 0.01)
            np.testing.assert_allclose(rep.q[0], start, atol=1e-6)
        # a start beyond the limits: the solution nearest it within the limits (J4 = 0.5 + π > 3.49)
        rep = validate_toolpath(fanuc, tp, start_q=q + [0, 0, 0, math.pi, 0, math.pi] + 0.01)
        assert rep.ok and fanuc.within_limits(rep.q[0])

    def test_sigma_floor_and_json(self, fanuc):
        Qj = fanuc_joint_path()
        rep = validate_toolpath(fanuc, ToolPath.from_poses(fanuc.fk(Qj)), start_q=Qj[0], sigma_min=0.02)
        sig = np.array([fanuc.sigma_min(q) for q in Qj])
        first = int(np.argmax(sig < 0.02))
        assert (rep.first_problem.index, rep.first_problem.kind) == (first, "sigma_min")
        assert rep.t is None and np.isnan(rep.joint_speed).all() and rep.first_problem.t is None
        d = json.loads(json.dumps(rep.to_dict(waypoints=True), allow_nan=False))
        assert d["valid"] is False and d["first_problem"]["kind"] == "sigma_min"
        assert d["waypoints"] == 200 and d["reachable"] == 200
        assert d["min_sigma"] == pytest.approx(float(sig.min()), rel=1e-6)
        assert len(d["per_waypoint"]["q"]) == 200 and set(d["counts"]) == set(KINDS)

    def test_ur3_drawing_starts_singular(self, pen):
        tp = load_toolpath(DRAWING, pen)
        ws = build_windows(pen, margin=0.05)
        rep = validate_toolpath(pen, tp, windows=ws, start_q=PEN_Q)
        assert rep.reachable.all()
        np.testing.assert_allclose(rep.q[0], PEN_Q, atol=1e-9)
        assert rep.sigma_min[0] < 1e-9                               # θ5 = 0: the wrist singularity
        p = rep.first_problem
        assert (p.index, p.kind) == (0, "window") and rep.window_name(0).startswith("wrist")
        assert "q5 = 0" in p.detail
        # the homework's branch keeps θ5 = 0 along the whole drawing: singular throughout
        assert np.abs(rep.q[:, 4]).max() < 1e-6
        for i in (0, 1234, 2500, 5000):
            np.testing.assert_allclose(fk_numpy(pen.chain, rep.q[i]), tp.poses[i], atol=2e-6)
        floor = validate_toolpath(pen, tp, start_q=PEN_Q, sigma_min=1e-3)
        assert (floor.first_problem.index, floor.first_problem.kind) == (0, "sigma_min")


# ====================================================================================== plots
def test_plot_writes_png(fanuc, fanuc_windows, tmp_path):
    from studies.plots.toolpath import plot_toolpath_report
    Qj = fanuc_joint_path(120)
    poses = fanuc.fk(Qj)
    poses[30, 2, 3] += 4.0
    rep = validate_toolpath(fanuc, ToolPath.from_poses(poses, feed=0.05), windows=fanuc_windows, start_q=Qj[0],
                            sigma_min=0.05)
    out = plot_toolpath_report(rep, fanuc, tmp_path / "sub" / "tp.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(out.parent.glob(".*.tmp"))


# ======================================================================================== CLI
def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_valid_path_exits_0(capsys):
    code, out, err = run(capsys, "validate-toolpath", "scara_rrp", str(SCARA_CSV))
    assert code == 0, err
    assert out.splitlines()[0].startswith("VALID")
    code, out, _ = run(capsys, "validate-toolpath", "scara_rrp", "scara_line", "--json")
    d = json.loads(out)
    assert code == 0 and d["valid"] is True and d["first_problem"] is None
    assert d["waypoints"] == 21 and d["reachable"] == 21 and d["min_sigma"] > 0
    assert d["units"]["length"] == "mm"
    np.testing.assert_allclose(d["length"], math.hypot(150, 450), rtol=1e-9)     # file unit: mm


def test_cli_invalid_path_exits_1(capsys, tmp_path):
    start = [str(x) for x in PEN_Q]
    png = tmp_path / "ur3.png"
    code, out, err = run(capsys, "validate-toolpath", "ur3_homework_pen", str(DRAWING), "--start", *start,
                         "--sigma-floor", "1e-3", "--json", "--plot", str(png))
    assert code == 1, err
    d = json.loads(out)
    assert d["valid"] is False and d["waypoints"] == 5001 and d["reachable"] == 5001
    assert d["first_problem"]["index"] == 0 and d["first_problem"]["kind"] == "sigma_min"
    assert d["min_sigma"] < 1e-9
    assert png.read_bytes()[:4] == b"\x89PNG"
    code, out, _ = run(capsys, "validate-toolpath", "ur3_homework_pen", "ur3_drawing", "--start", *start,
                       "--sigma-floor", "1e-3")
    assert code == 1 and out.splitlines()[0].startswith("INVALID: first problem at waypoint 0 of 5001")


@pytest.mark.parametrize("argv, words", [
    (["fanuc_m16ib20", "{tmp}/missing_z.csv"], ["line 1", "missing column", "z"]),
    (["fanuc_m16ib20", "{tmp}/nope.csv"], ["no such tool-path file"]),
    (["fanuc_m16ib20", "no_such_bundled_path"], ["bundled:", "ur3_drawing"]),
    (["fanuc_m16ib20", "{tmp}/bad.toml"], ["segments[0].type", "allowed: line, arc"]),
    (["fanuc_m16ib20", "scara_line", "--start", "1", "2"], ["--start", "6 joints"]),
    (["scara_rrp", "scara_line", "--start", "100", "100", "1e308"], ["--start", "joint 3 = 1e+308 mm", "±1e+09 mm"]),
    (["scara_rrp", "scara_line", "--start", "0", "0", "-1e308"], ["--start", "joint 3 = -1e+308 mm", "±1e+09 mm"]),
    (["no_robot", "scara_line"], ["unknown robot"]),
])
def test_cli_bad_input_exits_2(capsys, tmp_path, argv, words):
    write(tmp_path, "missing_z.csv", "x,y\n1,2\n")
    write(tmp_path, "bad.toml", '[start]\nxyz = [1, 0, 1]\n[[segments]]\ntype = "circle"\n')
    code, out, err = run(capsys, "validate-toolpath", *[a.format(tmp=tmp_path) for a in argv])
    assert code == 2 and out == ""
    assert err.startswith("rmt: error: ") and len(err.strip().splitlines()) == 1
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("start", [["1e308", "-1e308", "-100"], ["-1e308", "1e308", "-999999999"]])
def test_cli_huge_start_values_without_warnings(capsys, start):
    """Revolute joints at any finite angle and a prismatic one inside the evaluators' range (±1e9 mm)
    are a start like any other: the path is followed, stderr stays empty (no numpy RuntimeWarning,
    as --start 100 100 1e308 printed before it was refused)."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        code, out, err = run(capsys, "validate-toolpath", "scara_rrp", "scara_line", "--start", *start)
    assert code == 0 and out.startswith("VALID") and err == "", err


def test_api_start_q_beyond_the_evaluators_range_refused():
    scara = kin.load_robot("scara_rrp")
    tp = load_toolpath(SCARA_CSV, scara)
    with pytest.raises(kin.ConfigurationError, match=r"start_q: prismatic joint 3 = 1e\+308 m is beyond ±1e\+06 m"):
        validate_toolpath(scara, tp, start_q=[0.1, 0.2, 1e308])


def test_a_work_cell_flags_waypoints_and_motions_in_collision():
    """A tool path taught along a joint motion of the LR Mate; a box placed where the forearm passes
    half-way: the waypoints there are flagged ``collision`` (the world's own clearance agrees), the
    others are clear, and the per-waypoint clearance is the kernel's."""
    from kin.geometry import Obstacle, Shape
    from planning.collision import CollisionWorld

    robot = kin.load_robot("fanuc_lrmate200id")
    a, b = np.radians([-30, 15, 0, 0, -70, 0]), np.radians([30, 15, 0, 0, -70, 0])
    Q = a + np.linspace(0, 1, 61)[:, None] * (b - a)
    T = np.eye(4)
    T[:3, 3] = (0.3, 0.0, 0.7)
    world = CollisionWorld(robot, obstacles=[Obstacle("box", (Shape("box", (0.03, 0.03, 0.1), T),))])
    c = world.clearance(Q)
    assert c[0] > 0 and c[-1] > 0 and c.min() < 0
    report = validate_toolpath(robot, ToolPath.from_poses(robot.fk(Q)), start_q=a, world=world)
    assert report.reachable.all()
    np.testing.assert_allclose(report.clearance, world.clearance(report.q), atol=0)
    hit = report.flags["collision"]
    assert hit.any() and not hit[0] and not hit[-1]
    assert np.array_equal(hit & (report.clearance <= 0), report.clearance <= 0)
    assert report.first_problem.kind == "collision" and "obstacle 'box'" in report.first_problem.detail
    assert report.collision_check == "proven" and report.summary()["min_clearance"] == pytest.approx(c.min(), abs=2e-3)
