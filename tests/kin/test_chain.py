"""kin.chain: validation of Chain/Joint, configurations and limits, design-parameter vectors,
and the standard ↔ modified DH conversion (checked against the numpy FK of tests/dh_numpy.py and
against the product's FK)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import kin
from kin.chain import Chain, Joint, Parameter, Placement
from tests.chain_factory import random_chain, random_q
from tests.dh_numpy import fk_numpy, jacobian_numpy

ROBOTS = sorted(kin.bundled_robots())


def two_joint_chain(**kw) -> Chain:
    joints = (Joint("revolute", a=1.0, limits=(-1.0, 2.0), name="shoulder"),
              Joint("prismatic", a=0.5, limits=(0.1, 0.4), name="slide"))
    return Chain(name="two", joints=joints, **kw)


# ============================================================================== validation
class TestValidation:
    def test_no_joints(self):
        with pytest.raises(kin.ChainError, match="no joints"):
            Chain(name="empty", joints=())

    def test_bad_joint_type_lists_allowed(self):
        with pytest.raises(kin.ChainError) as e:
            Chain(name="x", joints=(Joint("revolute"), Joint("spherical")))  # type: ignore[arg-type]
        msg = str(e.value)
        assert "joint 2" in msg and "'spherical'" in msg and "revolute" in msg and "prismatic" in msg

    def test_bad_convention(self):
        with pytest.raises(kin.ChainError, match="standard, modified"):
            Chain(name="x", joints=(Joint("revolute"),), convention="craig")  # type: ignore[arg-type]

    @pytest.mark.parametrize("limits", [(1.0, -1.0), (0.5, 0.5), (-math.inf, 1.0), (0.0, math.nan)])
    def test_bad_limits(self, limits):
        with pytest.raises(kin.ChainError, match="joint 2: limits"):
            Chain(name="x", joints=(Joint("revolute"), Joint("revolute", limits=limits)))

    def test_undefined_parameter_names_it_and_the_defined_ones(self):
        params = {"L1": Parameter(1.0, (0.5, 2.0))}
        with pytest.raises(kin.ChainError) as e:
            Chain(name="x", joints=(Joint("revolute", a="L1"), Joint("revolute", d="L9")), parameters=params)
        msg = str(e.value)
        assert "joint 2" in msg and "'L9'" in msg and "L1" in msg and " d " in msg

    def test_parameter_kind_must_match_its_use(self):
        """An angle parameter declared as a length (the default kind) would be saved in the length unit
        and read back as an angle: 0.4 rad → 400 (mm) → 400° on reload.  The chain refuses it."""
        with pytest.raises(kin.ChainError, match=r"'TW'.*'angle'"):
            Chain(name="x", joints=(Joint("revolute", alpha="TW"),), parameters={"TW": Parameter(0.4, (-1.0, 1.0))})
        with pytest.raises(kin.ChainError, match=r"'L'.*'length'"):
            Chain(name="x", joints=(Joint("revolute", d="L"),), parameters={"L": Parameter(0.4, (0.0, 1.0), "angle")})
        with pytest.raises(kin.ChainError, match="'P'"):  # one parameter used as a length and as an angle
            Chain(name="x", joints=(Joint("revolute", a="P", theta="P"),), parameters={"P": Parameter(0.4, (0.0, 1.0))})
        Chain(name="x", joints=(Joint("revolute", a="L", alpha="TW"),),
              parameters={"L": Parameter(0.4, (0.0, 1.0)), "TW": Parameter(0.4, (-1.0, 1.0), "angle")})

    @pytest.mark.parametrize("label", ["base", "tool"])
    @pytest.mark.parametrize("placement, word", [
        (Placement(xyz=(math.nan, 0.0, 0.0)), "NaN"),
        (Placement(rpy=(0.0, math.inf, 0.0)), "NaN"),
        (Placement.from_matrix(np.diag([2.0, 2.0, 2.0, 1.0])), "rigid"),    # scaled
        (Placement.from_matrix(np.diag([1.0, 1.0, -1.0, 1.0])), "rigid"),   # mirrored (det −1)
    ], ids=["nan_xyz", "inf_rpy", "scaled", "mirrored"])
    def test_bad_placement(self, label, placement, word):
        """A NaN placement would make every FK silently NaN; a non-rigid one would distort it."""
        with pytest.raises(kin.ChainError, match=f"{label}.*{word}"):
            Chain(name="x", joints=(Joint("revolute", a=1.0),), **{label: placement})

    def test_non_finite_dh_value(self):
        with pytest.raises(kin.ChainError, match="alpha"):
            Chain(name="x", joints=(Joint("revolute", alpha=math.nan),))

    @pytest.mark.parametrize("task", [("x", "q"), ("x", "x"), ()])
    def test_bad_task(self, task):
        with pytest.raises(kin.ChainError, match="task"):
            Chain(name="x", joints=(Joint("revolute"),), task=task)

    def test_chain_error_is_an_rmt_error(self):
        assert issubclass(kin.ChainError, kin.RmtError)
        assert issubclass(kin.JointLimitError, kin.ConfigurationError)


# ====================================================================== configurations
class TestConfigurations:
    def test_as_batch_shapes(self):
        c = two_joint_chain()
        Q, single = c.as_batch([0.1, 0.2])
        assert Q.shape == (1, 2) and single is True
        Q, single = c.as_batch(np.zeros((5, 2)))
        assert Q.shape == (5, 2) and single is False
        Q, single = c.as_batch(np.zeros((0, 2)))
        assert Q.shape == (0, 2) and single is False
        assert Q.flags.c_contiguous
        Q, _ = c.as_batch(np.zeros((2, 5)).T[:, :2])  # a strided view comes back contiguous
        assert Q.flags.c_contiguous

    @pytest.mark.parametrize("q", [np.zeros(3), np.zeros((4, 3)), np.zeros((2, 2, 2)), 0.5, np.zeros((2, 1))])
    def test_as_batch_wrong_shape(self, q):
        with pytest.raises(kin.ConfigurationError, match=r"expected \(2,\) or \(N, 2\)"):
            two_joint_chain().as_batch(q)

    @pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
    def test_as_batch_non_finite(self, bad):
        c = two_joint_chain()
        with pytest.raises(kin.ConfigurationError, match="joint 2"):
            c.as_batch([0.0, bad])
        Q = np.zeros((3, 2))
        Q[2, 0] = bad
        with pytest.raises(kin.ConfigurationError, match=r"row 2, joint 1"):
            c.as_batch(Q)

    def test_within_limits(self):
        c = two_joint_chain()
        assert c.within_limits([0.0, 0.2]) is True
        assert c.within_limits([2.0, 0.1]) is True            # the limits themselves are inside
        assert c.within_limits([2.0 + 1e-9, 0.2]) is False
        assert c.within_limits([2.0 + 1e-9, 0.2], tol=1e-8) is True
        Q = np.array([[0.0, 0.2], [-1.5, 0.2], [0.0, 0.5], [1.9, 0.39]])
        ok = c.within_limits(Q)
        assert isinstance(ok, np.ndarray) and ok.tolist() == [True, False, False, True]

    def test_check_limits_names_the_joint(self):
        c = two_joint_chain()
        c.check_limits([0.5, 0.3])  # inside: no error
        with pytest.raises(kin.JointLimitError) as e:
            c.check_limits([0.5, 0.45])
        msg = str(e.value)
        assert "joint 2" in msg and "joint 1" not in msg and "0.45" in msg and "0.1" in msg and "0.4" in msg
        assert " m " in msg or msg.endswith(" m")  # prismatic: metres
        with pytest.raises(kin.JointLimitError, match=r"joint 1 = -1\.5 rad"):
            c.check_limits([-1.5, 0.45])  # the first offending joint

    def test_check_limits_checks_every_row_of_a_batch(self):
        c = two_joint_chain()
        c.check_limits(np.array([[0.0, 0.2], [1.0, 0.3]]))
        with pytest.raises(kin.JointLimitError, match="joint 2"):
            c.check_limits(np.array([[0.0, 0.2], [1.0, 0.9]]))

    def test_robot_check_limits_puma_theta5(self):
        # docs/machines.md §1: θ5 = 180° is outside PUMA's ±100°
        robot = kin.load_robot("puma560")
        with pytest.raises(kin.JointLimitError, match="joint 5"):
            robot.check_limits(np.radians([90, 30, 90, 60, 180, 0]))

    def test_joint_names_and_masks(self):
        c = two_joint_chain()
        assert c.joint_names() == ["shoulder", "slide"]
        assert c.revolute_mask.tolist() == [True, False]
        np.testing.assert_array_equal(c.limits, [[-1.0, 2.0], [0.1, 0.4]])


# ==================================================================== design parameters
class TestParameters:
    def chain(self) -> Chain:
        params = {"L1": Parameter(1.0, (0.5, 2.0)), "TW": Parameter(0.3, (-1.0, 1.0), "angle"),
                  "D2": Parameter(0.2, (0.0, 1.0))}
        joints = (Joint("revolute", a="L1", alpha="TW"), Joint("revolute", d="D2", a=0.4))
        return Chain(name="param", joints=joints, parameters=params)

    def test_nominal_vector(self):
        c = self.chain()
        assert c.parameter_names == ("L1", "TW", "D2")
        np.testing.assert_array_equal(c.parameter_vector(), [1.0, 0.3, 0.2])

    def test_mapping_overrides_only_given_names(self):
        np.testing.assert_array_equal(self.chain().parameter_vector({"D2": 0.7}), [1.0, 0.3, 0.7])
        np.testing.assert_array_equal(self.chain().parameter_vector({"TW": -0.5, "L1": 1.5}), [1.5, -0.5, 0.2])

    def test_full_vector_and_batch(self):
        c = self.chain()
        np.testing.assert_array_equal(c.parameter_vector([1.1, 0.2, 0.3]), [1.1, 0.2, 0.3])
        assert c.parameter_vector(np.zeros((4, 3))).shape == (4, 3)

    def test_unknown_name(self):
        with pytest.raises(kin.ParameterError) as e:
            self.chain().parameter_vector({"L3": 1.0})
        assert "'L3'" in str(e.value) and "L1, TW, D2" in str(e.value)

    @pytest.mark.parametrize("values", [[1.0, 2.0], np.zeros((2, 4)), [1.0, math.nan, 0.0]])
    def test_bad_vector(self, values):
        with pytest.raises(kin.ParameterError):
            self.chain().parameter_vector(values)

    def test_non_finite_mapping_value(self):
        with pytest.raises(kin.ParameterError, match="L1"):
            self.chain().parameter_vector({"L1": math.inf})

    def test_dh_table_and_with_parameters(self):
        c = self.chain()
        np.testing.assert_array_equal(c.dh_table(), [[1.0, 0.3, 0.0, 0.0], [0.4, 0.0, 0.2, 0.0]])
        np.testing.assert_array_equal(c.dh_table(np.array([2.0, -0.1, 0.5])), [[2.0, -0.1, 0, 0], [0.4, 0, 0.5, 0]])
        c2 = c.with_parameters({"L1": 1.7})
        assert c2.parameters["L1"].value == 1.7 and c2.parameters["L1"].bounds == (0.5, 2.0)
        assert c.parameters["L1"].value == 1.0  # the original is unchanged

    def test_frozen_gives_same_fk(self):
        c = self.chain()
        p = np.array([1.3, -0.4, 0.6])
        q = np.array([0.3, -1.1])
        f = c.frozen(p)
        assert f.parameters == {} and not any(isinstance(getattr(j, k), str)
                                              for j in f.joints for k in "a alpha d theta".split())
        np.testing.assert_allclose(fk_numpy(f, q), fk_numpy(c.with_parameters(dict(zip(c.parameter_names, p))), q),
                                   atol=1e-15)


# ========================================================================== conversion
def _same_fk_and_jacobian(orig: Chain, conv: Chain, Q: np.ndarray, robot_check: bool) -> None:
    for q in Q:
        T0 = fk_numpy(orig, q)
        np.testing.assert_allclose(fk_numpy(conv, q), T0, atol=1e-12)
        np.testing.assert_allclose(jacobian_numpy(conv, q), jacobian_numpy(orig, q), atol=1e-12)
    if robot_check:
        T = kin.Robot(conv).fk(Q)
        np.testing.assert_allclose(T, np.array([fk_numpy(orig, q) for q in Q]), atol=1e-12)


class TestConventionConversion:
    @pytest.mark.parametrize("name", ROBOTS)
    def test_bundled_to_modified_and_back(self, name):
        c = kin.load_chain(name)
        Q = random_q(c, 6, seed=len(name))
        mod = c.to_modified()
        assert mod.convention == "modified" and mod.n == c.n
        # the product's modified-DH FK too (compiled; a few robots suffice, random chains cover the rest)
        _same_fk_and_jacobian(c, mod, Q, robot_check=name in ("puma560", "cnc_rrrppp", "solar_concentrator",
                                                              "stanford_arm"))
        back = mod.to_standard()
        assert back.convention == "standard"
        _same_fk_and_jacobian(c, back, Q, robot_check=False)

    @pytest.mark.parametrize("seed", range(8))
    def test_random_chains(self, seed):
        std = random_chain(seed, params=bool(seed % 2), name=f"conv_{seed}")
        # a design parameter on the first/last row's a/alpha cannot move into base/tool: keep those numeric
        if isinstance(std.joints[-1].a, str) or isinstance(std.joints[-1].alpha, str):
            std = random_chain(seed, params=False, name=f"conv_{seed}")
        Q = random_q(std, 5, seed)
        mod = std.to_modified()
        _same_fk_and_jacobian(std, mod, Q, robot_check=seed < 3)
        _same_fk_and_jacobian(std, mod.to_standard(), Q, robot_check=False)
        # a chain written in modified DH from the start
        mod0 = random_chain(seed + 100, convention="modified", name=f"convm_{seed}")
        std0 = mod0.to_standard()
        assert std0.convention == "standard"
        _same_fk_and_jacobian(mod0, std0, random_q(mod0, 5, seed), robot_check=seed < 3)

    def test_same_convention_is_identity(self):
        c = kin.load_chain("puma560")
        assert c.to_standard() == c
        m = c.to_modified()
        assert m.to_modified() == m

    def test_parameters_survive_conversion(self):
        params = {"L2": Parameter(0.7, (0.3, 1.0))}
        c = Chain(name="p", joints=(Joint("revolute", a=0.2, alpha=0.5), Joint("revolute", a="L2", alpha=-1.0),
                                    Joint("prismatic", a=0.1, alpha=0.3, limits=(0.0, 0.5))), parameters=params)
        m = c.to_modified()
        assert m.joints[2].a == "L2"
        for v in (0.4, 0.9):
            Q = random_q(c, 3, 1)
            _same_fk_and_jacobian(c.with_parameters({"L2": v}), m.with_parameters({"L2": v}), Q, robot_check=False)

    @pytest.mark.parametrize("field", ["a", "alpha"])
    def test_refuses_to_move_a_parameter_into_the_tool(self, field):
        kind = "length" if field == "a" else "angle"
        params = {"P": Parameter(0.5, (0.0, 1.0), kind)}
        c = Chain(name="p", joints=(Joint("revolute", a=0.2), Joint("revolute", **{field: "P"})), parameters=params)
        with pytest.raises(kin.ChainError, match="modified"):
            c.to_modified()

    @pytest.mark.parametrize("field", ["a", "alpha"])
    def test_refuses_to_move_a_parameter_into_the_base(self, field):
        kind = "length" if field == "a" else "angle"
        params = {"P": Parameter(0.5, (0.0, 1.0), kind)}
        c = Chain(name="p", joints=(Joint("revolute", **{field: "P"}), Joint("revolute", a=0.2)),
                  parameters=params, convention="modified")
        with pytest.raises(kin.ChainError, match="standard"):
            c.to_standard()

    def test_planar_modified_by_hand(self):
        """Closed form: planar 2R arm (a1 = 1, a2 = 0.8) → p = (c1 + 0.8 c12, s1 + 0.8 s12, 0)."""
        m = kin.load_chain("planar_2r").to_modified()
        np.testing.assert_array_equal([j.a for j in m.joints], [0.0, 1.0])
        for t1, t2 in [(0.3, -1.2), (2.0, 0.5)]:
            p = kin.Robot(m).fk([t1, t2])[:3, 3]
            np.testing.assert_allclose(p, [math.cos(t1) + 0.8 * math.cos(t1 + t2),
                                           math.sin(t1) + 0.8 * math.sin(t1 + t2), 0.0], atol=1e-14)
