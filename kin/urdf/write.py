"""Writing a chain as URDF: one link per DH frame, simple cylinder visuals, collision capsules, the same FK.

Each DH row is split around its joint motion, A_i = Pre_i · M(q_i) · Post_i, with M a rotation
about z (revolute) or a translation along z (prismatic):

* standard: Pre = I,            Post = Rz(θ)·Tz(d)·Tx(a)·Rx(α)   (Tz(q) commutes with Rz(θ))
* modified: Pre = Rx(α)·Tx(a),  Post = Rz(θ)·Tz(d)                (Rz(θ) commutes with Tz(q))

URDF joint i then has axis z and origin Post_{i-1}·Pre_i (Post_0 = the base transform); a fixed
joint with origin Post_n·tool carries the ``tool`` link.  Design parameters are written at their
nominal values.  The XML is written with the standard library's ElementTree.

The collision capsules (the chain's geometry, else the default one, :attr:`kin.Robot.geometry`) are
written as <collision> elements of their body's link — URDF has no capsule, so each is a cylinder
along its segment and a sphere of its radius on each end, exactly the same solid (a ball when the
segment is a point).  A point p of DH frame k is Post_k·p in link k's frame, a point of frame 0 is
base·p in ``base_link``'s, the tool frame is the ``tool`` link's.  A body's inertial model (and the
payload, on the ``tool`` link) is written as an <inertial> element placed the same way.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from kin.chain import Chain
from kin.output import write_output
from kin.transforms import make_transform, matrix_to_rpy, rot_x, rot_z

GREY = "0.6 0.6 0.65 1"
ORANGE = "0.95 0.5 0.1 1"


def _tz(d: float) -> np.ndarray:
    return make_transform(None, [0.0, 0.0, d])


def _split(chain: Chain) -> list[tuple[np.ndarray, np.ndarray]]:
    """(Pre_i, Post_i) of every row of a chain without design parameters."""
    out = []
    for a, alpha, d, theta in chain.dh_table():
        if chain.convention == "standard":
            pre = np.eye(4)
            post = make_transform(rot_z(theta)) @ _tz(d) @ make_transform(rot_x(alpha), [a, 0.0, 0.0])
        else:
            pre = make_transform(rot_x(alpha)) @ make_transform(None, [a, 0.0, 0.0])
            post = make_transform(rot_z(theta)) @ _tz(d)
        out.append((pre, post))
    return out


def _num(x: float) -> str:
    x = float(x) + 0.0        # no "-0.0"
    return repr(x)


def _origin(parent: ET.Element, T: np.ndarray) -> None:
    ET.SubElement(parent, "origin", xyz=" ".join(_num(v) for v in T[:3, 3]),
                  rpy=" ".join(_num(v) for v in matrix_to_rpy(T[:3, :3])))


def _cylinder(link: ET.Element, T: np.ndarray, radius: float, length: float, colour: str) -> None:
    vis = ET.SubElement(link, "visual")
    _origin(vis, T)
    geo = ET.SubElement(vis, "geometry")
    ET.SubElement(geo, "cylinder", radius=_num(radius), length=_num(length))
    ET.SubElement(vis, "material", name=colour)


def _segment(link: ET.Element, p: np.ndarray, radius: float) -> None:
    """A cylinder from the link frame's origin to point ``p`` (link frame)."""
    length = float(np.linalg.norm(p))
    if length < 1e-9:
        return
    z = p / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    _cylinder(link, make_transform(np.column_stack([x, np.cross(z, x), z]), p / 2), radius, length, "rmt_grey")


def _frame_along(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """A frame at the midpoint of a–b with its z axis along b − a."""
    d = b - a
    z = d / np.linalg.norm(d)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return make_transform(np.column_stack([x, np.cross(z, x), z]), (a + b) / 2)


def _capsule(link: ET.Element, T: np.ndarray, a, b, radius: float, name: str) -> None:
    """A capsule (segment a–b in the body frame, ``T`` body frame → link frame) as a cylinder and two
    spheres; a ball when a = b."""
    pa = T[:3, :3] @ np.asarray(a, dtype=float) + T[:3, 3]
    pb = T[:3, :3] @ np.asarray(b, dtype=float) + T[:3, 3]
    ends = [pa] if np.linalg.norm(pb - pa) < 1e-12 else [pa, pb]
    if len(ends) == 2:
        col = ET.SubElement(link, "collision", name=f"{name}_cylinder")
        _origin(col, _frame_along(pa, pb))
        ET.SubElement(ET.SubElement(col, "geometry"), "cylinder", radius=_num(radius),
                      length=_num(float(np.linalg.norm(pb - pa))))
    for end, p in zip("ab", ends):
        col = ET.SubElement(link, "collision", name=f"{name}_{end}")
        _origin(col, make_transform(None, p))
        ET.SubElement(ET.SubElement(col, "geometry"), "sphere", radius=_num(radius))


def _inertial(link: ET.Element, li) -> None:
    """An <inertial> element: the centre of mass as its origin (no rotation: the tensor is written in
    the link frame's axes)."""
    el = ET.SubElement(link, "inertial")
    ET.SubElement(el, "origin", xyz=" ".join(_num(v) for v in li.com), rpy="0.0 0.0 0.0")
    ET.SubElement(el, "mass", value=_num(li.mass))
    ixx, iyy, izz, ixy, ixz, iyz = li.inertia
    ET.SubElement(el, "inertia", ixx=_num(ixx), ixy=_num(ixy), ixz=_num(ixz), iyy=_num(iyy), iyz=_num(iyz),
                  izz=_num(izz))


def _joint_names(chain: Chain) -> list[str]:
    names, seen = [], set()
    for i, nm in enumerate(chain.joint_names(), 1):
        nm = nm if nm not in seen else f"{nm}_{i}"
        seen.add(nm)
        names.append(nm)
    return names


def chain_to_urdf(chain: Chain) -> str:
    """URDF text of ``chain`` (SI: metres, radians): links ``base_link``, ``link_1``…``link_n``, ``tool``,
    each with its collision capsules."""
    chain = chain.frozen()
    parts = _split(chain)
    origins = [chain.base.matrix @ parts[0][0]]
    origins += [parts[i - 1][1] @ parts[i][0] for i in range(1, chain.n)]
    origins.append(parts[-1][1] @ chain.tool.matrix)            # the fixed tool joint
    size = sum(float(np.linalg.norm(T[:3, 3])) for T in origins)
    radius = max(0.005, 0.025 * size)

    robot = ET.Element("robot", name=chain.name)
    for name, rgba in (("rmt_grey", GREY), ("rmt_joint", ORANGE)):
        ET.SubElement(ET.SubElement(robot, "material", name=name), "color", rgba=rgba)
    links = ["base_link"] + [f"link_{i}" for i in range(1, chain.n + 1)] + ["tool"]
    from kin.geometry import default_geometry
    geometry = chain.geometry if chain.geometry is not None else default_geometry(chain)
    to_link = [chain.base.matrix] + [post for _, post in parts] + [np.eye(4)]     # body frame → link frame
    for k, lname in enumerate(links):
        link = ET.SubElement(robot, "link", name=lname)
        if k == 0:       # a pedestal under the base frame
            _cylinder(link, make_transform(None, [0.0, 0.0, -radius / 2]), 2.0 * radius, radius, "rmt_grey")
        elif lname != "tool":    # the joint that moves this link: a short cylinder along its axis (z)
            _cylinder(link, np.eye(4), 1.4 * radius, 3.0 * radius, "rmt_joint")
        if lname != "tool":
            _segment(link, origins[k][:3, 3], radius)
        for i, c in enumerate(geometry.capsules):
            if c.body == k:
                _capsule(link, to_link[k], c.a, c.b, c.radius, f"capsule_{i}")
        li = chain.joints[k - 1].inertia if 1 <= k <= chain.n else (chain.payload if lname == "tool" else None)
        if li is not None:
            _inertial(link, li.transformed(to_link[k]))
    for i, (j, jname) in enumerate(zip(chain.joints, _joint_names(chain))):
        el = ET.SubElement(robot, "joint", name=jname, type=j.type)
        ET.SubElement(el, "parent", link=links[i])
        ET.SubElement(el, "child", link=links[i + 1])
        _origin(el, origins[i])
        ET.SubElement(el, "axis", xyz="0 0 1")
        ET.SubElement(el, "limit", lower=_num(j.limits[0]), upper=_num(j.limits[1]), effort=_num(j.max_torque or 0.0),
                      velocity=_num(j.max_velocity or 0.0))
    el = ET.SubElement(robot, "joint", name="tool_joint", type="fixed")
    ET.SubElement(el, "parent", link=links[-2])
    ET.SubElement(el, "child", link="tool")
    _origin(el, origins[-1])
    ET.indent(robot)
    title = (chain.title or chain.name).replace("--", "- -").rstrip("-")   # "--" may not appear in a comment
    head = f"<?xml version=\"1.0\"?>\n<!-- {title}: written by rmtkit (rmt export-urdf) -->\n"
    return head + ET.tostring(robot, encoding="unicode") + "\n"


def save_urdf(chain: Chain, path: str | Path) -> Path:
    """Write ``chain`` as a URDF file through :func:`kin.output.write_output` (never replaces
    anything but a regular file; a temporary file beside it, then rename)."""
    return write_output(path, chain_to_urdf(chain))
