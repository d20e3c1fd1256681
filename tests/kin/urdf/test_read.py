"""Reading a URDF's serial chain (kin/urdf/read.py): the chain picked from the tree, the joints
refused, and every error a one-line RmtError naming the file and the element."""
from __future__ import annotations

import numpy as np
import pytest

from kin.errors import RmtError
from kin.urdf import UrdfError, read_serial_chain
from tests.kin.urdf.reference import YourdfpyFk
from tests.kin.urdf.synthetic import joint, serial, urdf_text, write_urdf


def tree(tmp_path):
    """base → j1 → arm → j2 → forearm → {j3 → hand, fixed → camera};  base → fixed → pedestal."""
    return write_urdf(tmp_path, [
        joint("j1", "revolute", "base", "arm", (0, 0, 0.3)),
        joint("j2", "revolute", "arm", "forearm", (0.4, 0, 0), axis=(0, 1, 0)),
        joint("j3", "prismatic", "forearm", "hand", (0.3, 0, 0), axis=(1, 0, 0), limits=(0.0, 0.2)),
        joint("cam", "fixed", "forearm", "camera", (0.1, 0.1, 0.1), (0.2, 0.3, 0.4)),
        joint("ped", "fixed", "base", "pedestal", (0, 0, -0.5)),
    ], "tree")


def test_branching_tree_needs_a_tip_and_lists_the_leaves(tmp_path):
    path = tree(tmp_path)
    with pytest.raises(UrdfError, match=r"tree.urdf: the tree below 'base' has 3 leaf links; choose the tip link "
                                        r"\(--tip\) from: hand, camera, pedestal"):
        read_serial_chain(path)


def test_tip_picks_the_branch(tmp_path):
    path = tree(tmp_path)
    sc = read_serial_chain(path, tip="camera")
    assert (sc.base, sc.tip, [j.name for j in sc.joints]) == ("base", "camera", ["j1", "j2"])
    sc = read_serial_chain(path, tip="hand")
    assert [j.type for j in sc.joints] == ["revolute", "revolute", "prismatic"]
    assert sc.joints[2].limits == (0.0, 0.2)
    ref = YourdfpyFk(path, "base", "hand")
    for q in np.random.default_rng(1).uniform([-2, -2, 0], [2, 2, 0.2], size=(20, 3)):
        np.testing.assert_allclose(sc.fk(q), ref(["j1", "j2", "j3"], q), atol=1e-14)


def test_default_chain_of_a_serial_urdf(tmp_path):
    path = write_urdf(tmp_path, serial([("revolute", (0, 0, 0.1), (0, 0, 0), (0, 0, 1)),
                                        ("fixed", (0, 0, 0.1), (0, 0, 0), (0, 0, 1))]))
    sc = read_serial_chain(path)
    assert (sc.base, sc.tip, sc.n) == ("l0", "l2", 1)
    np.testing.assert_allclose(sc.tip_offset[:3, 3], [0, 0, 0.1])


@pytest.mark.parametrize("kw, message", [
    (dict(tip="nowhere"), "tip link 'nowhere' is not defined; links: base, arm, forearm, hand, camera, pedestal"),
    (dict(base="nowhere", tip="hand"), "base link 'nowhere' is not defined"),
    (dict(base="hand", tip="camera"),
     "tip link 'camera' is not below base link 'hand'; links above it: forearm, arm, base"),
    (dict(base="arm", tip="pedestal"), "tip link 'pedestal' is not below base link 'arm'"),
    (dict(base="forearm", tip="camera"),
     "the chain 'forearm' → 'camera' has no revolute, continuous or prismatic joint"),
])
def test_bad_base_or_tip(tmp_path, kw, message):
    with pytest.raises(UrdfError, match=message):
        read_serial_chain(tree(tmp_path), **kw)


@pytest.mark.parametrize("type_, extra, message", [
    ("revolute", '<mimic joint="j1" multiplier="1" offset="0"/>',
     r"joint 'j2': a mimic joint \(its value follows joint 'j1'\) is not an independent joint"),
    ("floating", "", "joint 'j2': a floating joint .* is not a serial-chain joint"),
    ("planar", "", "joint 'j2': a planar joint .* is not a serial-chain joint"),
    ("spherical", "", "joint 'j2': type 'spherical' unknown; allowed: revolute, continuous, prismatic, fixed"),
])
def test_refused_joints(tmp_path, type_, extra, message):
    path = write_urdf(tmp_path, [joint("j1", "revolute", "a", "b"),
                                 joint("j2", type_, "b", "c", (0.2, 0, 0), extra=extra)], "refused")
    with pytest.raises(UrdfError, match=f"refused.urdf: {message}"):
        read_serial_chain(path)


def test_mimic_joint_off_the_chain_is_ignored(tmp_path):
    """A gripper finger that mimics another joint does not matter to the chain to another tip."""
    path = write_urdf(tmp_path, [joint("j1", "revolute", "a", "b"),
                                 joint("f1", "prismatic", "b", "finger1", axis=(1, 0, 0), limits=(0, 0.04)),
                                 joint("f2", "prismatic", "b", "finger2", axis=(-1, 0, 0), limits=(0, 0.04),
                                       extra='<mimic joint="f1"/>')], "gripper")
    assert [j.name for j in read_serial_chain(path, tip="finger1").joints] == ["j1", "f1"]
    with pytest.raises(UrdfError, match="joint 'f2': a mimic joint"):
        read_serial_chain(path, tip="finger2")


@pytest.mark.parametrize("mutate, message", [
    (lambda j: j.update(limits=None), r"joint 'j1': a revolute joint needs <limit lower=… upper=…>"),
    (lambda j: j.update(limits=(1.0, 1.0)),
     r"joint 'j1': <limit> lower = 1, upper = 1 must be finite with lower < upper"),
    (lambda j: j.update(limits=(-30.0, 30.0)), r"joint 'j1': <limit> \[-30, 30\] rad exceeds ±8π rad"),
    (lambda j: j.update(axis=(0, 0, 0)), r"joint 'j1': its <axis> \[0.0, 0.0, 0.0\] must be three finite numbers"),
    (lambda j: j.update(axis=(0, 0, "nan")), r"joint 'j1': its <axis> .* must be three finite numbers"),
    (lambda j: j.update(xyz=(0, "inf", 0)), r"joint 'j1': its <origin> holds a NaN or infinite value"),
    (lambda j: j.update(type="prismatic", axis=(0, 0, 2)),
     r"joint 'j1': the <axis> .* of a prismatic joint must be a unit vector"),
])
def test_bad_joint_elements(tmp_path, mutate, message):
    j = joint("j1", "revolute", "a", "b")
    mutate(j)
    path = tmp_path / "bad.urdf"
    path.write_text(urdf_text([j], "bad"))
    with pytest.raises(UrdfError, match=f"bad.urdf: {message}"):
        read_serial_chain(path)


def test_continuous_joint_is_revolute_over_one_turn(tmp_path):
    path = write_urdf(tmp_path, [joint("wheel", "continuous", "a", "b", limits=None, velocity=3.0)], "wheel")
    j = read_serial_chain(path).joints[0]
    assert (j.type, j.continuous, j.limits) == ("revolute", True, (-np.pi, np.pi))


@pytest.mark.parametrize("text, message", [
    ("<robot name='x'><link name='a'/><joint name='j' type='revolute'><parent link='a'/><child link='zz'/>"
     "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>",
     "joint 'j': its child link 'zz' is not defined"),
    ("<robot name='x'><link name='a'/><link name='b'/><link name='c'/>"
     "<joint name='j' type='fixed'><parent link='a'/><child link='b'/></joint>"
     "<joint name='k' type='fixed'><parent link='c'/><child link='b'/></joint></robot>",
     "joint 'k': link 'b' has two parent joints; a URDF must be a tree"),
    ("<robot name='x'><link name='a'/><link name='b'/></robot>", r"robot: the links form several trees.*roots: a, b"),
    ("<robot name='x'><link name='a'/><link name='a'/></robot>", "link 'a': two links have this name"),
    ("<robot name='x'></robot>", "robot: the URDF has no <link>"),
    ("this is not XML <", "robot: not a readable URDF"),
])
def test_malformed_files(tmp_path, text, message):
    path = tmp_path / "m.urdf"
    path.write_text(text)
    with pytest.raises(UrdfError, match=f"m.urdf: {message}"):
        read_serial_chain(path)


def test_missing_file_is_an_rmt_error(tmp_path):
    with pytest.raises(RmtError, match="nope.urdf: no such file"):
        read_serial_chain(tmp_path / "nope.urdf")


# ---- the tool: joints off the chain held, the default tip ------------------------------------------------
def gripper(tmp_path, finger_extra=""):
    """base → j1 → arm → j2 → flange; flange → tool0 and → camera (fixed); flange → finger1 (prismatic,
    limits 0.01 … 0.04), → finger2 (prismatic, mimics finger1 × −1 + 0.05), → spin (continuous),
    → flap (revolute, limits −1 … −0.5)."""
    return write_urdf(tmp_path, [
        joint("j1", "revolute", "base", "arm", (0, 0, 0.3)),
        joint("j2", "revolute", "arm", "flange", (0.4, 0, 0), axis=(0, 1, 0)),
        joint("t", "fixed", "flange", "tool0", (0.1, 0, 0), (0, 1.5707963267948966, 0)),
        joint("c", "fixed", "flange", "camera", (0, 0.05, 0), (0.3, 0, 0)),
        joint("finger1", "prismatic", "flange", "finger1", (0.05, 0.02, 0), axis=(0, 1, 0), limits=(0.01, 0.04)),
        joint("finger2", "prismatic", "flange", "finger2", (0.05, -0.02, 0), axis=(0, -1, 0), limits=(0.0, 0.04),
              extra='<mimic joint="finger1" multiplier="-1" offset="0.05"/>' + finger_extra),
        joint("spin", "continuous", "flange", "spinner", (0.02, 0, 0.03), (0.1, 0.2, 0.3), axis=(1, 0, 0),
              limits=None),
        joint("flap", "revolute", "flange", "flap", (0.02, 0, -0.03), axis=(0, 0, 1), limits=(-1.0, -0.5)),
    ], "gripper")


def test_joints_off_the_chain_below_the_last_joint_are_held_on_the_tool(tmp_path):
    """Held at 0 clipped into the limits (finger1: 0.01, flap: −0.5, spin: 0) and a mimic at multiplier ×
    its leader + offset (finger2: −0.01 + 0.05); each link's pose is yourdfpy's at those values."""
    path = gripper(tmp_path)
    sc = read_serial_chain(path, tip="tool0")
    held = {name: (q, how) for name, q, how in sc.held}
    assert held == {"finger1": (0.01, "the limit nearest 0"), "finger2": (pytest.approx(0.04), "mimic of finger1"),
                    "spin": (0.0, "0"), "flap": (-0.5, "the limit nearest 0")}
    body = {lk.name: lk.body for lk in sc.links}
    assert {body[n] for n in ("tool0", "camera", "finger1", "finger2", "spinner", "flap")} == {sc.n + 1}
    assert body["flange"] == sc.n and not sc.loose_links
    import yourdfpy
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    model.update_cfg({"finger1": 0.01, "spin": 0.0, "flap": -0.5})        # yourdfpy sets the mimic itself
    for lk in sc.links:
        np.testing.assert_allclose(lk.pose, model.get_transform(lk.name, "base"), atol=1e-15, err_msg=lk.name)


def test_a_mimic_of_a_chain_joint_is_left_out(tmp_path):
    """A joint that follows a joint of the chain moves relative to the tool: not held, its link left out."""
    path = write_urdf(tmp_path, [joint("j1", "revolute", "a", "b"), joint("j2", "revolute", "b", "c", (0.3, 0, 0)),
                                 joint("f", "revolute", "c", "d", (0.1, 0, 0), extra='<mimic joint="j2"/>')], "m")
    path.write_text(path.read_text().replace('<link name="d"/>', '<link name="d"><collision><geometry>'
                                             '<sphere radius="0.01"/></geometry></collision></link>'))
    sc = read_serial_chain(path, tip="c")
    assert sc.held == () and sc.loose_links == ("d",)


def test_default_tip_is_where_leaves_meet_through_fixed_and_mimic_joints(tmp_path):
    """Leaves that differ only by fixed joints and a mimic of a chain joint: the tip is the flange, said so."""
    path = write_urdf(tmp_path, [
        joint("j1", "revolute", "base", "arm", (0, 0, 0.3)),
        joint("j2", "revolute", "arm", "flange", (0.4, 0, 0), axis=(0, 1, 0)),
        joint("t", "fixed", "flange", "hand", (0.1, 0, 0)),
        joint("tcp", "fixed", "hand", "tcp", (0.1, 0, 0)),
        joint("cam", "fixed", "hand", "camera", (0, 0.1, 0)),
        joint("f", "revolute", "hand", "finger", (0, 0, 0.05), extra='<mimic joint="j2"/>'),
    ], "fixed_leaves")
    sc = read_serial_chain(path)
    assert sc.tip == "hand" and [j.name for j in sc.joints] == ["j1", "j2"]
    assert sc.tip_note == ("tip 'hand': the link that all 3 leaves hang from through fixed and mimic joints "
                           "(tcp, camera, finger: another tip with --tip)")


def test_leaves_on_different_movable_joints_still_need_a_tip(tmp_path):
    """finger1 moves on its own (not a mimic): the leaves differ in their movable joints — the error lists them."""
    with pytest.raises(UrdfError, match=r"the tree below 'base' has 6 leaf links; choose the tip link \(--tip\) "
                                        r"from: tool0, camera, finger1, finger2, spinner, flap"):
        read_serial_chain(gripper(tmp_path))


@pytest.mark.parametrize("mutate, message", [
    (lambda j: j.update(xyz=(0, 1e300, 0)),
     r"joint 'j1': its <origin> xyz \[0.0, 1e\+300, 0.0\] reaches 1e\+300 m; allowed: at most 10000 m \(10 km\)"),
    (lambda j: j.update(velocity=-1.0), r"joint 'j1': <limit> velocity = -1; allowed: a finite number ≥ 0 \(rad/s"),
    (lambda j: j.update(extra="", velocity=float("nan")), r"joint 'j1': <limit> velocity = nan; allowed"),
    (lambda j: j.update(type="prismatic", limits=(1e-12, 0.2)),
     r"joint 'j1': <limit> lower = 1e-12 m; allowed: 0 or 1e-09 to 10000 m in magnitude"),
    (lambda j: j.update(type="prismatic", limits=(0.0, 2e4)),
     r"joint 'j1': <limit> upper = 20000 m; allowed: 0 or 1e-09 to 10000 m"),
])
def test_numbers_a_robot_file_cannot_hold_are_refused(tmp_path, mutate, message):
    j = joint("j1", "revolute", "a", "b")
    mutate(j)
    path = tmp_path / "bad.urdf"
    path.write_text(urdf_text([j], "bad"))
    with pytest.raises(UrdfError, match=f"bad.urdf: {message}") as e:
        read_serial_chain(path)
    assert "\n" not in str(e.value)


def test_an_effort_beyond_a_robot_files_range_is_refused(tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text(urdf_text([joint("j1", "revolute", "a", "b")], "bad").replace('effort="10"', 'effort="1e8"'))
    with pytest.raises(UrdfError, match=r"joint 'j1': <limit> effort = 1e\+08; allowed: 0 to 1e\+07 \(N·m; 0: unk"):
        read_serial_chain(path)
