"""Independent references for the URDF tests (a helper, not a test module).

* :func:`erd_urdf` finds a URDF shipped by the ``example-robot-data`` package (a test dependency);
  :func:`mbm_urdf` robowflex's spherized Panda or UR5 (MotionBenchMaker's robots, fetched once);
* :class:`YourdfpyFk` is yourdfpy's own forward kinematics of a URDF (its scene graph), the tip
  link's pose in the base link's frame;
* :class:`PinocchioModel` is pinocchio's model of a URDF: the tip frame's pose and its geometric
  Jacobian in the LOCAL_WORLD_ALIGNED convention (rows v of the frame origin, then ω, world axes),
  which is rmtkit's convention when the base link is the URDF's root.
"""
from __future__ import annotations

import importlib.metadata
from pathlib import Path

import numpy as np
import pytest

ERD_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"


def erd_urdf(relative: str) -> Path:
    """Path of a URDF inside the installed example-robot-data package (skips when it is absent)."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install rmtkit[test])")
    path = Path(dist.locate_file(f"{ERD_ROBOTS}/{relative}"))
    if not path.is_file():
        pytest.skip(f"example-robot-data {dist.version} does not ship {relative}")
    return path


def mbm_urdf(robot: str) -> Path:
    """robowflex's spherized URDF of ``robot`` ("panda" or "ur5"), as MotionBenchMaker uses it
    (:func:`studies.benchmarks.mbm.robot_files`; skips, saying why, when it cannot be had)."""
    from studies.benchmarks.mbm import MbmDataError, robot_files
    try:
        return robot_files(robot)[0]
    except MbmDataError as e:
        pytest.skip(str(e))


class YourdfpyFk:
    """yourdfpy's forward kinematics; joint values by name, every other joint at 0."""

    def __init__(self, path, base: str, tip: str):
        import yourdfpy
        self.urdf = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
        self.base, self.tip = base, tip

    def __call__(self, names, q) -> np.ndarray:
        self.urdf.update_cfg({n: float(v) for n, v in zip(names, q)})
        return np.asarray(self.urdf.get_transform(self.tip, self.base), dtype=float)


class PinocchioModel:
    """pinocchio's model of a URDF (fixed base at the root link); skips when pinocchio is absent."""

    def __init__(self, path, tip: str):
        pin = pytest.importorskip("pinocchio", reason="pinocchio (pip package pin, the bench extra) is not installed")
        self.pin = pin
        self.model = pin.buildModelFromUrdf(str(path))
        self.data = self.model.createData()
        self.frame = self.model.getFrameId(tip, pin.FrameType.BODY)
        assert self.frame < self.model.nframes, f"pinocchio has no body frame {tip!r}"

    def q_of(self, names, q) -> tuple[np.ndarray, list[int]]:
        """pinocchio's configuration vector and the velocity index of each named joint.

        A continuous joint has two configuration entries in pinocchio (cos q, sin q)."""
        qp = self.pin.neutral(self.model)
        cols = []
        for n, v in zip(names, q):
            jm = self.model.joints[self.model.getJointId(n)]
            if jm.nq == 2:
                qp[jm.idx_q:jm.idx_q + 2] = np.cos(v), np.sin(v)
            else:
                qp[jm.idx_q] = v
            cols.append(jm.idx_v)
        return qp, cols

    def fk_and_jacobian(self, names, q) -> tuple[np.ndarray, np.ndarray]:
        pin = self.pin
        qp, cols = self.q_of(names, q)
        pin.computeJointJacobians(self.model, self.data, qp)
        pin.updateFramePlacements(self.model, self.data)
        T = self.data.oMf[self.frame].homogeneous
        J = pin.getFrameJacobian(self.model, self.data, self.frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        return np.array(T), np.array(J)[:, cols]
