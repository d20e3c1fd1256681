"""URDF <inertial> elements: imported into the DH frames of the bodies, checked against the URDF's XML
read here with ElementTree and numpy alone (link poses at q = 0 from the joint origins), then
exported and read back."""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from kin.dynamics import LinkInertia
from kin.urdf import chain_to_urdf, import_urdf
from kin.urdf.errors import UrdfError
from tests.dh_numpy import frames_numpy
from tests.kin.urdf.reference import erd_urdf

CASES = [("panda_description/urdf/panda.urdf", "panda_link8"), ("ur_description/urdf/ur5_robot.urdf", "tool0")]
IDS = ["panda", "ur5"]


def _rpy(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _origin(el):
    T = np.eye(4)
    o = None if el is None else el.find("origin")
    if o is not None:
        T[:3, :3] = _rpy(*[float(x) for x in o.get("rpy", "0 0 0").split()])
        T[:3, 3] = [float(x) for x in o.get("xyz", "0 0 0").split()]
    return T


def _held(joints, name, on_path):
    """The value a joint off the chain is held at, from the XML: 0 clipped into its limits, a mimic
    joint at multiplier × its leader's + offset; None when it follows a joint of the chain."""
    j = joints[name]
    mimic = j.find("mimic")
    if mimic is not None:
        lead = mimic.get("joint")
        if lead in on_path:
            return None
        q = _held(joints, lead, on_path)
        return None if q is None else float(mimic.get("multiplier", 1)) * q + float(mimic.get("offset", 0))
    lim = j.find("limit")
    if lim is None or j.get("type") == "continuous":
        return 0.0
    return min(max(0.0, float(lim.get("lower", 0))), float(lim.get("upper", 0)))


def _motion(j, q):
    axis = np.array([float(x) for x in (j.find("axis").get("xyz") if j.find("axis") is not None else "1 0 0").split()])
    axis /= np.linalg.norm(axis)
    M = np.eye(4)
    if j.get("type") == "prismatic":
        M[:3, 3] = q * axis
    else:
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        M[:3, :3] = np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K
    return M


def xml_bodies(path, tip):
    """From the XML: the links of the chain root → tip (and what is fixed to them), each link's pose at
    q = 0, which body it rides on (joint count along the path; below the last joint's own link, through
    fixed joints and joints off the chain held at 0 clipped into their limits: n + 1), its mass and its
    centre of mass (base frame)."""
    root = ET.parse(path).getroot()
    joints = root.findall("joint")
    by_name = {j.get("name"): j for j in joints}
    parent = {j.find("child").get("link"): j for j in joints}
    links = {lk.get("name"): lk for lk in root.findall("link")}
    base = next(n for n in links if n not in parent)
    chain, link = [], tip
    while link != base:
        chain.append(parent[link])
        link = parent[link].find("parent").get("link")
    chain.reverse()
    movable = [j.get("name") for j in chain if j.get("type") != "fixed"]
    n = len(movable)
    last = by_name[movable[-1]].find("child").get("link")
    pose, body = {base: np.eye(4)}, {base: 0}
    stack = [base]
    while stack:
        lk = stack.pop()
        below = body[lk] == n + 1 or lk == last
        for j in joints:
            if j.find("parent").get("link") != lk:
                continue
            child = j.find("child").get("link")
            if j.get("type") == "fixed":
                body[child] = n + 1 if below else body[lk]
                pose[child] = pose[lk] @ _origin(j)
            elif j.get("name") in movable:
                body[child] = movable.index(j.get("name")) + 1
                pose[child] = pose[lk] @ _origin(j)
            elif below and _held(by_name, j.get("name"), movable) is not None:
                body[child] = n + 1                        # a gripper finger, held
                pose[child] = pose[lk] @ _origin(j) @ _motion(j, _held(by_name, j.get("name"), movable))
            else:
                continue
            stack.append(child)
    out = {}
    for name, T in pose.items():
        el = links[name].find("inertial")
        if el is None:
            continue
        m = float(el.find("mass").get("value"))
        c = (T @ _origin(el))[:3, 3]
        k = body[name]
        M, C = out.get(k, (0.0, np.zeros(3)))
        out[k] = (M + m, C + m * c)
    return {k: (m, C / m if m else C) for k, (m, C) in out.items() if m > 0}, n


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("relative, tip", CASES, ids=IDS)
def test_masses_and_centres_of_mass_match_the_xml(relative, tip, convention):
    path = erd_urdf(relative)
    chain = import_urdf(str(path), tip=tip, convention=convention, collision=False)
    ref, n = xml_bodies(str(path), tip)
    frames = frames_numpy(chain, np.zeros(chain.n))
    tool = frames[-1] @ chain.tool.matrix
    total = sum(j.inertia.mass for j in chain.joints if j.inertia) + (chain.payload.mass if chain.payload else 0.0)
    assert math.isclose(total, sum(m for k, (m, _) in ref.items() if k > 0), rel_tol=1e-12)
    for k in range(1, n + 2):
        li = chain.joints[k - 1].inertia if k <= n else chain.payload
        if k not in ref:
            assert li is None or li.mass == 0.0
            continue
        F = frames[k] if k <= n else tool
        m, c = ref[k]
        assert math.isclose(li.mass, m, rel_tol=1e-12), k
        np.testing.assert_allclose(F[:3, :3] @ li.com + F[:3, 3], c, atol=1e-12, err_msg=f"body {k}")


def test_panda_payload_is_the_hand_and_its_fingers_held():
    """The fingers' prismatic joints (one mimics the other) are held at 0 and ride with the hand: the
    payload is 0.73 + 2 × 0.015 kg (the URDF's masses), and the source says where they are held."""
    chain = import_urdf(str(erd_urdf("panda_description/urdf/panda.urdf")), tip="panda_link8", collision=False)
    assert math.isclose(chain.payload.mass, 0.73 + 2 * 0.015)
    assert "held at panda_finger_joint1 = 0 (0), panda_finger_joint2 = 0 (mimic of panda_finger_joint1)" in chain.source
    assert "left out" not in chain.source


def test_tensor_is_turned_into_the_body_frame():
    """UR5 link 2's tensor is diagonal in its link frame: in DH frame 2 it is R·I·Rᵀ with R the frame change,
    so its eigenvalues stay and the base-frame tensor agrees in both conventions."""
    path = str(erd_urdf("ur_description/urdf/ur5_robot.urdf"))
    std = import_urdf(path, tip="tool0", collision=False)
    mod = import_urdf(path, tip="tool0", convention="modified", collision=False)
    q = np.array([0.3, -1.0, 0.7, 0.2, -0.4, 1.1])
    for k, (F1, F2) in enumerate(zip(frames_numpy(std, q)[1:], frames_numpy(mod, q)[1:])):
        a, b = std.joints[k].inertia, mod.joints[k].inertia
        np.testing.assert_allclose(F1[:3, :3] @ a.tensor @ F1[:3, :3].T, F2[:3, :3] @ b.tensor @ F2[:3, :3].T,
                                   atol=1e-15)
    np.testing.assert_allclose(np.linalg.eigvalsh(std.joints[1].inertia.tensor),
                               sorted([0.226890675907, 0.226890675907, 0.0151074]), rtol=1e-9)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_export_and_import_give_the_same_inertial_model(tmp_path, convention):
    path = str(erd_urdf("panda_description/urdf/panda.urdf"))
    chain = import_urdf(path, tip="panda_link8", convention=convention, collision=False)
    out = tmp_path / "panda_again.urdf"
    out.write_text(chain_to_urdf(chain))
    again = import_urdf(str(out), tip="tool", convention=convention, collision=False)
    for a, b in zip(chain.joints, again.joints):
        assert LinkInertia.is_close(a.inertia, b.inertia, 1e-12)
    assert LinkInertia.is_close(chain.payload, again.payload, 1e-12)


URDF = """<robot name="r">
  <link name="a"/>
  <link name="b"><inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="{m}"/>
    <inertia ixx="{ixx}" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


@pytest.mark.parametrize("m, ixx, text", [("-1", "1", "mass = -1 kg"), ("1", "3", "triangle inequality"),
                                          ("1", "-1", "not positive semi-definite"), ("nan", "1", "NaN")])
def test_unphysical_inertial_is_one_line_naming_the_link(tmp_path, m, ixx, text):
    p = tmp_path / "r.urdf"
    p.write_text(URDF.format(m=m, ixx=ixx))
    with pytest.raises(UrdfError) as e:
        import_urdf(str(p), collision=False)
    msg = str(e.value)
    assert "\n" not in msg and "link 'b' inertial" in msg and text in msg, msg


def test_two_links_on_one_body_combine_by_the_parallel_axis_theorem(tmp_path):
    p = tmp_path / "r.urdf"
    p.write_text("""<robot name="r"><link name="a"/>
  <link name="b"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><origin xyz="0 0 0"/><mass value="3"/>
    <inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="d"/>
  <joint name="f" type="fixed"><parent link="b"/><child link="c"/><origin xyz="-0.1 0 0"/></joint>
  <joint name="j2" type="revolute"><parent link="c"/><child link="d"/><axis xyz="1 0 0"/>
    <origin xyz="0 0 0.5"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>""")
    chain = import_urdf(str(p), tip="d", collision=False)
    li = chain.joints[0].inertia
    assert li.mass == 4.0 and chain.payload is None and chain.joints[1].inertia is None
    frame = frames_numpy(chain, [0.0, 0.0])[1]
    c = frame[:3, :3] @ li.com + frame[:3, 3]
    np.testing.assert_allclose(c, [(0.1 - 0.3) / 4, 0, 0], atol=1e-15)
    # about the common COM (x = -0.05): 0.01 + 0.02, and the y and z moments gain Σ m d² = 1·0.15² + 3·0.05²
    R = frame[:3, :3]
    np.testing.assert_allclose(R @ li.tensor @ R.T, np.diag([0.03, 0.03 + 0.03, 0.03 + 0.03]), atol=1e-15)


def test_bundled_panda_carries_the_urdf_inertials():
    """franka_panda's [joints.inertial] tables are the URDF's links 1–7, in the file's own DH frames: at
    random configurations every body's centre of mass and tensor (base frame) equal the URDF's."""
    import kin

    path = str(erd_urdf("panda_description/urdf/panda.urdf"))
    urdf = import_urdf(path, tip="panda_link8", convention="modified", collision=False)
    bundled = kin.load_chain("franka_panda")
    assert "<inertial> elements of panda_link1 to panda_link7" in bundled.source
    assert bundled.payload is None
    for q in kin.Robot(bundled).random_configurations(20, seed=3):
        for F1, F2, j1, j2 in zip(frames_numpy(urdf, q)[1:], frames_numpy(bundled, q)[1:], urdf.joints,
                                  bundled.joints):
            a, b = j1.inertia, j2.inertia
            assert a.mass == b.mass
            np.testing.assert_allclose(F1[:3, :3] @ a.com + F1[:3, 3], F2[:3, :3] @ b.com + F2[:3, 3], atol=1e-12)
            np.testing.assert_allclose(F1[:3, :3] @ a.tensor @ F1[:3, :3].T, F2[:3, :3] @ b.tensor @ F2[:3, :3].T,
                                       atol=1e-12)


def test_a_placeholder_inertial_is_left_out_with_a_warning(tmp_path):
    """Mass 0 with a tensor (robowflex's Panda gives panda_link8 one): a warning naming the link, the body
    gets no inertia from it, and the source says so; the other link's mass is kept."""
    from kin.urdf import UrdfWarning
    p = tmp_path / "r.urdf"
    p.write_text(URDF.format(m="0", ixx="1").replace('<link name="a"/>', '''<link name="a"/>
  <link name="c"><inertial><mass value="2"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="f" type="fixed"><parent link="b"/><child link="c"/><origin xyz="0.2 0 0"/></joint>'''))
    with pytest.warns(UrdfWarning, match=r"r.urdf: link 'b' inertial: mass 0 with the inertia tensor diagonal 1 1 1 "
                                         r"\(a placeholder of a massless link\): left out") as record:
        chain = import_urdf(str(p), tip="c", collision=False)
    assert len(record) == 1
    assert chain.payload.mass == 2.0 and chain.joints[0].inertia is None
    assert "placeholder inertials (mass 0 with a tensor) left out: b" in chain.source
