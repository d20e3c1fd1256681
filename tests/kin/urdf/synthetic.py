"""Small URDFs written for the tests (a helper, not a test module).

:func:`urdf_text` writes a URDF from joint descriptions; links are made from the joints' parents
and children.  :func:`random_urdf` draws a serial chain with random origins, axes (often along a
coordinate axis, sometimes parallel to or through the previous one), joint types and fixed joints.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


def joint(name, type_, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=(0, 0, 1), limits=(-2.0, 2.0),
          velocity=None, extra="") -> dict:
    return dict(name=name, type=type_, parent=parent, child=child, xyz=xyz, rpy=rpy, axis=axis, limits=limits,
                velocity=velocity, extra=extra)


def urdf_text(joints: list[dict], name: str = "synthetic") -> str:
    links = []
    for j in joints:
        for lk in (j["parent"], j["child"]):
            if lk not in links:
                links.append(lk)
    out = ['<?xml version="1.0"?>', f'<robot name="{name}">']
    out += [f'  <link name="{lk}"/>' for lk in links]
    for j in joints:
        out.append(f'  <joint name="{j["name"]}" type="{j["type"]}">')
        out.append(f'    <parent link="{j["parent"]}"/><child link="{j["child"]}"/>')
        out.append('    <origin xyz="{}" rpy="{}"/>'.format(
            *(" ".join(repr(float(v)) for v in j[k]) for k in ("xyz", "rpy"))))
        if j["type"] != "fixed":
            out.append('    <axis xyz="{}"/>'.format(" ".join(repr(float(v)) for v in j["axis"])))
        if j["limits"] is not None and j["type"] in ("revolute", "prismatic"):
            vel = j["velocity"] if j["velocity"] is not None else 1.0
            out.append(f'    <limit lower="{j["limits"][0]}" upper="{j["limits"][1]}" effort="10" velocity="{vel}"/>')
        out.append(f'    {j["extra"]}')
        out.append('  </joint>')
    out.append('</robot>')
    return "\n".join(out) + "\n"


def write_urdf(tmp_path: Path, joints: list[dict], name: str = "synthetic") -> Path:
    path = tmp_path / f"{name}.urdf"
    path.write_text(urdf_text(joints, name))
    return path


def serial(specs: list[tuple], name: str = "synthetic") -> list[dict]:
    """A serial chain l0 → l1 → … from (type, xyz, rpy, axis) tuples; joints j1, j2, … (fixed ones f1, …)."""
    out, k = [], 0
    for i, (type_, xyz, rpy, axis) in enumerate(specs):
        k += type_ != "fixed"
        nm = f"j{k}" if type_ != "fixed" else f"f{i + 1}"
        limits = (-0.3, 0.4) if type_ == "prismatic" else (-2.5, 2.5)
        out.append(joint(nm, type_, f"l{i}", f"l{i + 1}", xyz, rpy, axis, limits))
    return out


def random_urdf(seed: int) -> list[dict]:
    """A random serial chain of 3 to 7 movable joints with fixed joints in between."""
    rng = np.random.default_rng(seed)
    specs = [("fixed", rng.uniform(-0.3, 0.3, 3), rng.uniform(-3, 3, 3), (0, 0, 1))]
    prev_axis = np.array([0.0, 0.0, 1.0])
    for _ in range(int(rng.integers(3, 8))):
        u = rng.uniform()
        if u < 0.3:
            axis = np.eye(3)[rng.integers(3)] * rng.choice([-1.0, 1.0])
        elif u < 0.45:
            axis = prev_axis                                 # parallel to the previous one in its own frame
        else:
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
        # sometimes through the previous origin
        xyz = rng.uniform(-0.4, 0.4, 3) if rng.uniform() > 0.2 else np.zeros(3)
        rpy = rng.uniform(-3, 3, 3) if rng.uniform() > 0.4 else np.zeros(3)
        if rng.uniform() < 0.3:
            specs.append(("fixed", rng.uniform(-0.2, 0.2, 3), rng.uniform(-3, 3, 3), (0, 0, 1)))
        specs.append(("prismatic" if rng.uniform() < 0.2 else "revolute", xyz, rpy, axis))
        prev_axis = axis
    specs.append(("fixed", rng.uniform(-0.2, 0.2, 3), rng.uniform(-3, 3, 3), (0, 0, 1)))
    return serial(specs, f"random_{seed}")
