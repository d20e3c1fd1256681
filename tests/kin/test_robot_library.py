"""The bundled robot library against the reference document (docs/machines.md).

Every reference value is checked to the precision it is printed with: a number printed with k
decimals must match within half a unit of its last digit; a number printed without decimals (the
0/±1 entries of rotation matrices, the SCARA's 675 mm) is an exact value and must match within 1e-9
of its unit.  The expected numbers below are copied from docs/machines.md (or from the maker's document
named in the test), never from this code's own output.

Each forward-kinematics check runs twice: with the independent numpy implementation in
``tests/dh_numpy.py`` and with the product API ``kin.load_robot(name).fk(q)`` (4×4, SI units).
The product tests are skipped while ``kin.load_robot`` does not exist yet.
"""
from __future__ import annotations

import dataclasses
import math
import zlib
from pathlib import Path

import numpy as np
import pytest

import kin
from kin.chain import Chain, Joint, Placement
from kin.robotfile import ROBOT_DIR, bundled_robots, dumps_robot, load_chain, loads_robot, save_robot
from tests.dh_numpy import fk_numpy, frames_numpy, jacobian_numpy

DEG = math.pi / 180.0
MM = 1e-3
INCH = 0.0254

HAS_PRODUCT_API = callable(getattr(kin, "load_robot", None))
needs_product = pytest.mark.skipif(not HAS_PRODUCT_API,
                                   reason="kin.load_robot is not available yet (kin/__init__.py in progress)")

EXPECTED_ROBOTS = {
    "puma560", "scara_rrp", "fanuc_m16ib20", "cnc_rrrppp", "stanford_arm", "ur3_homework",
    "solar_concentrator", "planar_2r", "spherical_rrp", "ur5e", "ur10e", "abb_irb120",
    "franka_panda", "kuka_iiwa7", "kuka_iiwa14", "ur3e", "ur16e", "kinova_gen3", "fanuc_lrmate200id",
}


# ---- printed numbers -------------------------------------------------------------------------
def printed(text: str, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Numbers as printed in the reference (row separators ';' or ','), and their tolerances.

    Returns (values, atol), both multiplied by ``scale`` (the unit → SI factor).  The tolerance
    is half a unit of the last printed digit, or 1e-9 for a number printed without decimals.
    """
    values, tols = [], []
    for tok in text.replace(";", " ").replace(",", " ").replace("[", " ").replace("]", " ").split():
        values.append(float(tok))
        tols.append(0.5 * 10.0 ** -len(tok.split(".")[1]) if "." in tok else 1e-9)
    return np.array(values) * scale, np.array(tols) * scale


def assert_printed(actual, text: str, scale: float = 1.0, what: str = "") -> None:
    """``actual`` (any shape, SI) equals the printed numbers ``text`` (in units of ``scale``)."""
    expected, atol = printed(text, scale)
    actual = np.asarray(actual, dtype=float).ravel()
    assert actual.shape == expected.shape, f"{what}: {actual.size} values, reference prints {expected.size}"
    err = np.abs(actual - expected)
    bad = err > atol + 1e-12
    assert not bad.any(), (f"{what}: got {np.array2string(actual / scale, precision=6)} (reference units), "
                           f"reference {text!r}; off at entries {np.flatnonzero(bad).tolist()}")


# ---- the two FK implementations --------------------------------------------------------------
@pytest.fixture(params=["numpy", pytest.param("product", marks=needs_product)])
def fk(request):
    """fk(name, q_SI) -> 4×4 SI, by the numpy re-implementation or by the product."""
    if request.param == "numpy":
        return lambda name, q: fk_numpy(load_chain(name), q)

    def product_fk(name, q):
        T = np.asarray(kin.load_robot(name).fk(np.asarray(q, dtype=float)), dtype=float)
        assert T.shape == (4, 4)
        return T
    return product_fk


def tz(z: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = z
    return T


def bisect(f, lo: float, hi: float, tol: float = 1e-14) -> float:
    """A root of f on [lo, hi] (f(lo), f(hi) of opposite signs)."""
    flo = f(lo)
    assert flo * f(hi) < 0, "no sign change"
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        fm = f(mid)
        if (fm < 0) == (flo < 0):
            lo, flo = mid, fm
        else:
            hi = mid
    return 0.5 * (lo + hi)


# ======================================================================================= library
class TestLibraryFiles:
    def test_expected_robots_are_bundled(self):
        missing = EXPECTED_ROBOTS - set(bundled_robots())
        assert not missing, f"robot files missing from {ROBOT_DIR}: {sorted(missing)}"

    @pytest.mark.parametrize("name", sorted(EXPECTED_ROBOTS))
    def test_file_name_matches_name_field(self, name):
        chain = load_chain(ROBOT_DIR / f"{name}.toml")
        assert chain.name == name

    @pytest.mark.parametrize("path", sorted(ROBOT_DIR.glob("*.toml")), ids=lambda p: p.stem)
    def test_every_file_loads_and_cites_a_source(self, path: Path):
        chain = load_chain(path)
        assert chain.name == path.stem
        assert chain.title.strip()
        assert len(chain.source.strip()) > 20, "source must say where the numbers come from"
        assert chain.convention in ("standard", "modified")

    @pytest.mark.parametrize("name", sorted(bundled_robots()))
    def test_dump_load_round_trip_is_identical(self, name):
        chain = load_chain(name)
        again = loads_robot(dumps_robot(chain))
        assert again == chain

    @pytest.mark.parametrize("name", sorted(bundled_robots()))
    def test_revolute_limits_are_plausible_radians(self, name):
        # a degree value read as radians would give |limit| of tens or hundreds of rad
        chain = load_chain(name)
        for j in chain.joints:
            if j.is_revolute:
                assert max(abs(j.limits[0]), abs(j.limits[1])) <= 8 * math.pi


# ========================================================================= §1 PUMA 560 (mm, deg)
class TestPuma560:
    def test_table_6_1_in_si(self):
        c = load_chain("puma560")
        assert (c.length_unit, c.angle_unit, c.convention) == ("mm", "deg", "standard")
        assert_printed(c.dh_table()[:, 0], "0 431.8 -20.32 0 0 0", MM, "a")
        assert_printed(c.dh_table()[:, 1], "-90 0 90 -90 90 0", DEG, "alpha")
        assert_printed(c.dh_table()[:, 2], "0 149.09 0 433.07 0 56.25", MM, "d")
        assert_printed(c.dh_table()[:, 3], "0 0 0 0 0 0", DEG, "theta offsets (the table's theta is a configuration)")
        assert_printed(c.limits, "-160 160; -225 45; -45 225; -110 170; -100 100; -266 266", DEG, "limits")

    def test_fk_example_configuration(self, fk):
        T = fk("puma560", np.array([90, 0, 90, 0, 0, 0]) * DEG)
        assert_printed(T[:3, 3], "-149.09 921.12 20.32", MM, "p")
        assert_printed(T[:3, :3], "0 -1 0; 0 0 1; -1 0 0", 1.0, "R")
        assert_printed(T[3], "0 0 0 1")

    def test_fk_zero(self, fk):
        T = fk("puma560", np.zeros(6))
        assert_printed(T[:3, 3], "411.48 149.09 489.32", MM, "p")
        assert_printed(T[:3, :3], "1 0 0; 0 1 0; 0 0 1", 1.0, "R")

    def test_slides_version_in_metres(self):
        # the slides: a3 = +0.02032 m, same alphas; q = (pi/2, 0, pi/2, 0, 0, 0)
        c = load_chain("puma560")
        joints = list(c.joints)
        joints[2] = dataclasses.replace(joints[2], a=0.02032)
        slides = dataclasses.replace(c, joints=tuple(joints))
        T = fk_numpy(slides, [math.pi / 2, 0, math.pi / 2, 0, 0, 0])
        assert_printed(T[:3], "0 -1 0 -0.1491; 0 0 1 0.9211; -1 0 0 -0.0203", 1.0, "T (slides)")

    @pytest.mark.parametrize("a3", [-20.32 * MM, 0.02032], ids=["table", "slides"])
    def test_jacobian_determinant_factors(self, a3):
        c = load_chain("puma560")
        joints = list(c.joints)
        joints[2] = dataclasses.replace(joints[2], a=a3)
        c = dataclasses.replace(c, joints=tuple(joints))
        a2, d4 = 431.8 * MM, 433.07 * MM
        rng = np.random.default_rng(560)
        for q in rng.uniform(-math.pi, math.pi, size=(20, 6)):
            c2, c3, s3 = math.cos(q[1]), math.cos(q[2]), math.sin(q[2])
            c23, s23 = math.cos(q[1] + q[2]), math.sin(q[1] + q[2])
            expected = a2 * math.sin(q[4]) * (d4 * c3 - a3 * s3) * (a2 * c2 + a3 * c23 + d4 * s23)
            assert np.linalg.det(jacobian_numpy(c, q)) == pytest.approx(expected, rel=1e-9, abs=1e-13)

    def test_zero_is_a_wrist_singularity(self):
        c = load_chain("puma560")
        assert abs(np.linalg.det(jacobian_numpy(c, np.zeros(6)))) < 1e-12

    def test_thesis_theta5_180_is_out_of_limits(self):
        c = load_chain("puma560")
        q = np.array([90, 30, 90, 60, 180, 0]) * DEG
        assert c.within_limits(q) is False
        bad = c.limit_violations(q)
        assert [i for i, _, _ in bad] == [5]
        _, value, (lo, hi) = bad[0]
        assert value == pytest.approx(180 * DEG)
        assert (lo, hi) == pytest.approx((-100 * DEG, 100 * DEG))
        # the same configuration with theta5 inside +-100 deg is accepted
        assert c.within_limits(np.array([90, 30, 90, 60, 100, 0]) * DEG) is True


class TestConfigurationTest:
    """§1: a = d = 0, theta = (90, 30, 90, 60, 180) deg, alpha = (-90, 60, 90, 90, 0) deg."""

    THETA = np.array([90, 30, 90, 60, 180]) * DEG
    ALPHA = np.array([-90, 60, 90, 90, 0]) * DEG
    R5 = ".866 0 -.5; -.25 -.866 -.433; -.433 .5 -.75"

    def chain(self) -> Chain:
        joints = tuple(Joint("revolute", a=0.0, alpha=float(al), d=0.0, theta=0.0) for al in self.ALPHA)
        return Chain(name="configuration_test", joints=joints, convention="standard")

    def test_corrected_rotation_five_joints(self):
        T = fk_numpy(self.chain(), self.THETA)
        assert_printed(T[:3, :3], self.R5, 1.0, "R (5 joints)")
        # a = d = 0: the position is the origin (the thesis printed row sums instead)
        assert_printed(T[:3, 3], "0 0 0", 1.0, "p")

    @needs_product
    def test_corrected_rotation_five_joints_product(self, tmp_path):
        path = save_robot(self.chain(), tmp_path / "configuration_test.toml")
        T = np.asarray(kin.load_robot(str(path)).fk(self.THETA), dtype=float)
        assert_printed(T[:3, :3], self.R5, 1.0, "R (5 joints)")
        assert_printed(T[:3, 3], "0 0 0", 1.0, "p")


# ============================================================================ §2 SCARA (mm, rad)
class TestScara:
    def test_limits_in_si(self):
        c = load_chain("scara_rrp")
        assert c.joint_types == ("revolute", "revolute", "prismatic")
        assert_printed(c.limits[:2], "-2.22 2.22; -2.53 2.53", 1.0, "revolute limits (rad)")
        assert_printed(c.limits[2], "-297 -97", MM, "prismatic limits")
        assert c.task == ("x", "y", "z")

    def test_fk_stretched(self, fk):
        T = fk("scara_rrp", [0.0, 0.0, -197 * MM])
        assert_printed(T[:3, 3], "675 0 -195", MM, "FK(0, 0, -197)")

    def test_fk_general(self, fk):
        T = fk("scara_rrp", [0.5, 1.0, -150 * MM])
        assert_printed(T[:3, 3], "229.29 556.74 -148", MM, "FK(0.5, 1.0, -150)")

    def test_position_jacobian_determinant(self):
        c = load_chain("scara_rrp")
        for q in ([0.3, 0.9, -150 * MM], [-1.0, -2.0, -250 * MM], [2.0, 0.4, -100 * MM]):
            det = np.linalg.det(jacobian_numpy(c, q)[:3])
            # 101250 sin(theta2) mm^2 -> m^2
            assert det == pytest.approx(101250 * MM**2 * math.sin(q[1]), rel=1e-9)
        assert abs(np.linalg.det(jacobian_numpy(c, [0.7, 0.0, -200 * MM])[:3])) < 1e-15

    def test_stretched_reach(self):
        T = fk_numpy(load_chain("scara_rrp"), [1.1, 0.0, -200 * MM])
        assert_printed(math.hypot(T[0, 3], T[1, 3]), "675", MM, "r at theta2 = 0")


# ========================================================================== §3 FANUC (m, rad)
class TestFanuc:
    def test_table_16(self):
        c = load_chain("fanuc_m16ib20")
        assert_printed(c.dh_table()[:, 2], "0.525 0 0 0.740 0 0.100", 1.0, "d")
        assert_printed(c.dh_table()[:, 0], "0.150 0.770 0.100 0 0 0", 1.0, "a")
        assert_printed(c.limits, "-2.97 2.97; -1.57 2.79; -2.97 5.06; -3.49 3.49; -2.44 2.44; -7.85 7.85")
        h = math.pi / 2
        np.testing.assert_allclose(c.dh_table()[:, 1], [-h, 0, h, -h, h, 0], atol=1e-15)

    def test_fk_zero(self, fk):
        T = fk("fanuc_m16ib20", np.zeros(6))
        assert_printed(T[:3, :3], "1 0 0; 0 1 0; 0 0 1", 1.0, "R")
        assert_printed(T[:3, 3], "1.02 0 1.365", 1.0, "p")

    def test_three_singular_factors(self):
        """Wrist (theta5 = 0), elbow and shoulder singularities all make det J vanish."""
        c = load_chain("fanuc_m16ib20")
        det = lambda q: np.linalg.det(jacobian_numpy(c, q))
        generic = np.array([0.3, 0.4, 0.5, 0.6, 0.7, 0.8])
        assert abs(det(generic)) > 1e-3
        # wrist: theta5 = 0
        assert abs(det(np.where(np.arange(6) == 4, 0.0, generic))) < 1e-12

        # elbow: the wrist centre lies in the plane of the parallel axes 2 and 3
        def elbow_residual(q3):
            f = frames_numpy(c, np.r_[generic[:2], q3, generic[3:]])
            o1, z1, o2, wc = f[1][:3, 3], f[1][:3, 2], f[2][:3, 3], f[4][:3, 3]
            return float(np.dot(wc - o1, np.cross(z1, o2 - o1)))
        q3 = bisect(elbow_residual, 0.5, 2.0)
        assert abs(det(np.r_[generic[:2], q3, generic[3:]])) < 1e-9

        # shoulder: the wrist centre lies on the axis of joint 1 (x = y = 0 at theta1 = 0)
        def shoulder_residual(q2):
            return float(frames_numpy(c, np.r_[0.0, q2, generic[2:]])[4][0, 3])
        q2 = bisect(shoulder_residual, 1.0, 2.5)
        assert abs(det(np.r_[0.0, q2, generic[2:]])) < 1e-9


# ============================================================================ §4 CNC RRRPPP (m)
class TestCnc:
    def test_table_19(self):
        c = load_chain("cnc_rrrppp")
        assert c.joint_types == ("revolute",) * 3 + ("prismatic",) * 3
        h = math.pi / 2
        # fixed theta of the prismatic joints: -90, 90, -90 degrees, in radians
        np.testing.assert_allclose(c.dh_table()[3:, 3], [-h, h, -h], atol=1e-15)
        assert_printed(c.dh_table()[:, 0], "0.6 0.5 0.5 0.4 0.5 0.5", 1.0, "a")
        assert_printed(c.dh_table()[:3, 2], "0.5 0.5 0.5", 1.0, "d (revolute rows)")
        assert_printed(c.limits, "-1.74 1.74; -1.74 1.74; -1.74 1.74; -0.4 0.4; -0.3 0.3; -0.4 0.4")

    def test_det_j_proportional_to_sin_theta2(self):
        c = load_chain("cnc_rrrppp")
        rng = np.random.default_rng(19)
        Q = rng.uniform(c.lower, c.upper, size=(20, 6))
        Q = Q[np.abs(np.sin(Q[:, 1])) > 0.1]
        ratios = [np.linalg.det(jacobian_numpy(c, q)) / math.sin(q[1]) for q in Q]
        assert np.ptp(ratios) < 1e-9 * max(1.0, abs(ratios[0]))
        assert abs(ratios[0]) > 1e-3
        q = Q[0].copy()
        q[1] = 0.0
        assert abs(np.linalg.det(jacobian_numpy(c, q))) < 1e-12


# ======================================================================== §5 Stanford arm (m)
class TestStanford:
    @pytest.mark.parametrize("q, printed_T", [
        ([0, 0, 1, 0, 0, 0], "1 0 0 0; 0 1 0 0.2; 0 0 1 1.2"),
        ([0, 0, 1, 0, math.pi / 2, 0], "0 0 1 0.2; 0 1 0 0.2; -1 0 0 1"),
        ([0, 0, 1, math.pi / 2, math.pi / 2, 0], "0 -1 0 0; 0 0 1 0.4; -1 0 0 1"),
    ], ids=["d3=1", "theta5=90", "theta4=theta5=90"])
    def test_fk(self, fk, q, printed_T):
        T = fk("stanford_arm", q)
        assert_printed(T[:3], printed_T, 1.0, "T")

    def test_det_j(self):
        c = load_chain("stanford_arm")
        rng = np.random.default_rng(5)
        for q in rng.uniform(c.lower, c.upper, size=(10, 6)):
            expected = q[2] ** 2 * math.sin(q[1]) * math.sin(q[4])
            assert np.linalg.det(jacobian_numpy(c, q)) == pytest.approx(expected, rel=1e-9, abs=1e-14)

    def test_d2_d6_and_prismatic_joint3(self):
        c = load_chain("stanford_arm")
        assert c.joints[2].type == "prismatic"
        assert_printed([c.resolve(c.joints[1].d), c.resolve(c.joints[5].d)], "0.2 0.2")


# ===================================================================== §6 "UR3-like" arm (m)
class TestUr3Homework:
    POSITIONS = [
        ([0, 0, 0, 0, 0, 0], "-0.1723 0 1.42391"),
        ([180, 0, 0, 0, 0, 0], "0.1723 0 1.42391"),
        ([0, 90, 0, 0, 0, 0], "-0.1723 -1.24061 0.1833"),
        ([0, 0, 90, 0, 0, 0], "-0.1723 -0.5033 0.92061"),
        ([0, 0, 0, 90, 0, 0], "-0.1723 -0.1155 1.30841"),
        ([0, 0, 0, 0, 180, 0], "-0.0187 0 1.42391"),
    ]
    PEN_Q = np.array([0, 0, 90, -90, 0, 0]) * DEG
    PEN_P = "-0.2173 -0.3878 1.03611"

    @pytest.mark.parametrize("q_deg, p", POSITIONS, ids=lambda v: str(v))
    def test_positions(self, fk, q_deg, p):
        T = fk("ur3_homework", np.array(q_deg) * DEG)
        assert_printed(T[:3, 3], p, 1.0, f"p at q = {q_deg} deg")

    def test_zero_rotation(self, fk):
        T = fk("ur3_homework", np.zeros(6))
        assert_printed(T[:3, :3], "0 0 -1; -1 0 0; 0 1 0", 1.0, "R at q = 0")

    def test_offsets_and_flange(self):
        c = load_chain("ur3_homework")
        assert_printed(c.dh_table()[:, 3], "90 90 0 90 0 0", DEG, "theta offsets")
        assert_printed(c.resolve(c.joints[5].d), "0.0768", 1.0, "d6 (flange)")

    def test_pen_by_replacing_d6(self):
        c = load_chain("ur3_homework")
        joints = list(c.joints)
        joints[5] = dataclasses.replace(joints[5], d=0.1218)
        pen = dataclasses.replace(c, joints=tuple(joints))
        T = fk_numpy(pen, self.PEN_Q)
        assert_printed(T[:3, 3], self.PEN_P, 1.0, "pen tip")
        # a singular pose (theta5 = 0)
        assert abs(np.linalg.det(jacobian_numpy(pen, self.PEN_Q))) < 1e-12

    def test_pen_as_tool_placement(self):
        c = load_chain("ur3_homework")
        pen = dataclasses.replace(c, tool=Placement(xyz=(0.0, 0.0, 0.1218 - 0.0768)))
        assert_printed(fk_numpy(pen, self.PEN_Q)[:3, 3], self.PEN_P, 1.0, "pen tip")

    @needs_product
    def test_pen_product(self):
        # the pen lengthens d6 along z6: FK_pen = FK_flange · Tz(0.1218 - 0.0768)
        T = np.asarray(kin.load_robot("ur3_homework").fk(self.PEN_Q), dtype=float) @ tz(0.1218 - 0.0768)
        assert_printed(T[:3, 3], self.PEN_P, 1.0, "pen tip")


# ================================================================ §7 solar concentrator (in, deg)
class TestSolarConcentrator:
    NOMINAL = np.array([90, 0, 0, -90, 0, 90]) * DEG

    def test_nominal_is_not_an_offset(self):
        c = load_chain("solar_concentrator")
        assert (c.length_unit, c.angle_unit) == ("in", "deg")
        assert_printed(c.dh_table()[:, 3], "0 0 0 0 0 0", DEG, "offsets")
        assert_printed(c.dh_table()[:, 0], "0 62.6 0 46 0 3.1", INCH, "a")
        assert_printed(c.dh_table()[:, 2], "0 6.9 17.7 4.5 39.7 0", INCH, "d")

    def test_base_and_tool(self):
        c = load_chain("solar_concentrator")
        assert_printed(c.base.matrix[3], "0 0 0 1", 1.0, "base bottom row")
        assert_printed(c.tool.matrix[3], "0 0 0 1", 1.0, "tool bottom row")
        assert_printed(c.base.matrix[:3, :3], "-1 0 0; 0 -1 0; 0 0 1", 1.0, "base R")
        assert_printed(c.base.matrix[:3, 3], "-21.4 0 0", INCH, "base p")
        assert_printed(c.tool.matrix[:3, :3], "0 -1 0; 0 0 1; -1 0 0", 1.0, "tool R")
        assert_printed(c.tool.matrix[:3, 3], "0 0 0", INCH, "tool p")

    def test_t6_at_nominal(self):
        c = load_chain("solar_concentrator")
        bare = dataclasses.replace(c, base=Placement(), tool=Placement())
        T6 = fk_numpy(bare, self.NOMINAL)
        assert_printed(T6[:3, :3], "0 1 0; 1 0 0; 0 0 -1", 1.0, "T6 R")
        assert_printed(T6[:3, 3], "-21.4 105.4 -4.5", INCH, "T6 p")

    @needs_product
    def test_t6_at_nominal_product(self):
        c = load_chain("solar_concentrator")
        T = np.asarray(kin.load_robot("solar_concentrator").fk(self.NOMINAL), dtype=float)
        T6 = np.linalg.inv(c.base.matrix) @ T @ np.linalg.inv(c.tool.matrix)
        assert_printed(T6[:3, :3], "0 1 0; 1 0 0; 0 0 -1", 1.0, "T6 R")
        assert_printed(T6[:3, 3], "-21.4 105.4 -4.5", INCH, "T6 p")

    def test_base_t6_tool_at_nominal(self, fk):
        T = fk("solar_concentrator", self.NOMINAL)
        assert_printed(T[:3, :3], "0 0 -1; 0 1 0; 1 0 0", 1.0, "Base·T6·Tool R")
        assert_printed(T[:3, 3], "0 -105.4 -4.5", INCH, "Base·T6·Tool p")


# ================================================================ §8 small textbook chains (m)
class TestSmallChains:
    def test_spherical_rrp_closed_form(self, fk):
        c = load_chain("spherical_rrp")
        assert c.joints[2].type == "prismatic"
        assert_printed(c.resolve(c.joints[0].d), "3", 1.0, "d1")
        rng = np.random.default_rng(8)
        for _ in range(10):
            t1, t2 = rng.uniform(-math.pi, math.pi, 2)
            d3 = rng.uniform(*c.limits[2])
            p = fk("spherical_rrp", [t1, t2, d3])[:3, 3]
            expected = [-d3 * math.cos(t1) * math.sin(t2), -d3 * math.sin(t1) * math.sin(t2), 3 - d3 * math.cos(t2)]
            np.testing.assert_allclose(p, expected, atol=1e-12)

    def test_planar_2r_closed_form(self, fk):
        c = load_chain("planar_2r")
        a1, a2 = c.resolve(c.joints[0].a), c.resolve(c.joints[1].a)
        assert_printed([a1, a2], "1.0 0.8", 1.0, "a1, a2 (chosen in the file)")
        assert c.task == ("x", "y")
        rng = np.random.default_rng(2)
        for t1, t2 in rng.uniform(-math.pi, math.pi, size=(10, 2)):
            T = fk("planar_2r", [t1, t2])
            expected = [a1 * math.cos(t1) + a2 * math.cos(t1 + t2), a1 * math.sin(t1) + a2 * math.sin(t1 + t2), 0.0]
            np.testing.assert_allclose(T[:3, 3], expected, atol=1e-12)
            np.testing.assert_allclose(T[:3, 2], [0, 0, 1], atol=1e-12)

    def test_planar_2r_det_jv(self):
        c = load_chain("planar_2r")
        for t1, t2 in [(0.1, 0.7), (-2.0, 2.5), (1.0, -0.3)]:
            det = np.linalg.det(jacobian_numpy(c, [t1, t2])[:2])
            assert det == pytest.approx(1.0 * 0.8 * math.sin(t2), rel=1e-12)


# ================================================================== industrial arms (makers' data)
class TestUniversalRobots:
    """Universal Robots' published DH tables (support article 'DH parameters for calculations of
    kinematics and dynamics'); at q = 0 the flange is at (a2 + a3, -(d4 + d6), d1 - d5)."""

    def test_ur5e_flange_at_zero(self, fk):
        T = fk("ur5e", np.zeros(6))
        assert_printed(T[:3, 3], "-0.8172 -0.2329 0.0628", 1.0, "UR5e flange at q = 0")

    def test_ur10e_flange_at_zero(self, fk):
        T = fk("ur10e", np.zeros(6))
        assert_printed(T[:3, 3], "-1.18425 -0.2907 0.06085", 1.0, "UR10e flange at q = 0")

    def test_ur5e_table_limits_and_speeds(self):
        c = load_chain("ur5e")
        assert_printed(c.dh_table()[:, 0], "0 -0.425 -0.3922 0 0 0", 1.0, "a")
        assert_printed(c.dh_table()[:, 2], "0.1625 0 0 0.1333 0.0997 0.0996", 1.0, "d")
        assert_printed(c.dh_table()[:, 1], "90 0 0 90 -90 0", DEG, "alpha")
        assert_printed(c.limits, "-360 360; " * 6, DEG, "limits")
        assert_printed([j.max_velocity for j in c.joints], "180 " * 6, DEG, "max speed")

    def test_ur10e_table_limits_and_speeds(self):
        c = load_chain("ur10e")
        assert_printed(c.dh_table()[:, 0], "0 -0.6127 -0.57155 0 0 0", 1.0, "a")
        assert_printed(c.dh_table()[:, 2], "0.1807 0 0 0.17415 0.11985 0.11655", 1.0, "d")
        assert_printed(c.limits, "-360 360; " * 6, DEG, "limits")
        assert_printed([j.max_velocity for j in c.joints], "120 120 180 180 180 180", DEG, "max speed")


class TestAbbIrb120:
    """ABB Product specification IRB 120 (3HAC035960-001): dimensions 290/270/70/302/72 mm,
    wrist centre at (302, 630) mm in the calibration pose, reach 0.58 m."""

    def test_flange_and_wrist_centre_at_calibration_pose(self, fk):
        T = fk("abb_irb120", np.zeros(6))
        assert_printed(T[:3, 3], "374 0 630", MM, "flange at q = 0")
        # the flange faces forward (+x); tool0's x axis points down
        assert_printed(T[:3, 2], "1 0 0", 1.0, "flange z axis")
        assert_printed(T[:3, 0], "0 0 -1", 1.0, "flange x axis")
        wrist_centre = T[:3, 3] - 72 * MM * T[:3, 2]
        assert_printed(wrist_centre, "302 0 630", MM, "wrist centre at q = 0")

    def test_reach(self):
        """Largest distance of the wrist centre from axis 2 over axis 3's range: 0.58 m."""
        c = load_chain("abb_irb120")
        q3 = np.linspace(c.limits[2, 0], c.limits[2, 1], 3601)
        dist = []
        for v in q3:
            f = frames_numpy(c, [0.0, 0.0, v, 0.0, 0.0, 0.0])
            dist.append(np.linalg.norm(f[4][:3, 3] - f[1][:3, 3]))
        assert_printed(max(dist), "0.58", 1.0, "reach")

    def test_ranges_and_speeds(self):
        c = load_chain("abb_irb120")
        assert_printed(c.limits, "-165 165; -110 110; -110 70; -160 160; -120 120; -400 400", DEG, "ranges")
        assert_printed([j.max_velocity for j in c.joints], "250 250 250 320 320 420", DEG, "max speeds")


# ===================================================================== numpy vs product, broadly
@needs_product
@pytest.mark.parametrize("name", sorted(EXPECTED_ROBOTS))
def test_product_fk_matches_numpy_everywhere(name):
    chain = load_chain(name)
    robot = kin.load_robot(name)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    for q in rng.uniform(chain.lower, chain.upper, size=(25, chain.n)):
        np.testing.assert_allclose(np.asarray(robot.fk(q), dtype=float), fk_numpy(chain, q), atol=1e-9)


# ============================================================= the numpy helper checks itself
def test_numpy_helper_modified_convention_agrees_with_elementary_transforms():
    """dh_numpy's modified-DH matrix equals Rx(α)·Tx(a)·Rz(θ)·Tz(d) composed from elementary ones."""
    from tests.dh_numpy import dh_modified, rot_x_h, rot_z_h, trans_h
    rng = np.random.default_rng(0)
    for theta, d, a, alpha in rng.uniform(-2, 2, size=(10, 4)):
        expected = rot_x_h(alpha) @ trans_h(x=a) @ rot_z_h(theta) @ trans_h(z=d)
        np.testing.assert_allclose(dh_modified(theta, d, a, alpha), expected, atol=1e-14)


def test_numpy_helper_modified_chain_gives_same_fk():
    """A hand-written modified-DH table of the planar 2R arm (a0 = 0, a1 = 1, a2 = 0.8 in the tool)."""
    joints = (Joint("revolute", a=0.0, alpha=0.0), Joint("revolute", a=1.0, alpha=0.0))
    mod = Chain(name="planar_2r_modified", joints=joints, convention="modified",
                tool=Placement(xyz=(0.8, 0.0, 0.0)))
    for t1, t2 in [(0.3, -1.2), (2.0, 0.5)]:
        p = fk_numpy(mod, [t1, t2])[:3, 3]
        np.testing.assert_allclose(p, [math.cos(t1) + 0.8 * math.cos(t1 + t2),
                                       math.sin(t1) + 0.8 * math.sin(t1 + t2), 0.0], atol=1e-12)
