"""MotionBenchMaker problems for rmtkit: a scene as a work cell (``rmt import-scene``'s reader), a
request's start and goal in a robot's joint order, and the robots as robot files (``rmt import-urdf``'s
importer)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Problem", "problems", "request_states", "scene_cell_of", "import_robot", "TIPS"]

#: the tool link of each robot's import (None: the importer's default, the link every leaf hangs from
#: through fixed joints — the Panda's hand, the UR5's flange link); the gripper below is the tool's geometry
TIPS = {"panda": None, "ur5": None}


@dataclass(frozen=True)
class Problem:
    robot: str
    scene: str
    index: int
    scene_file: Path
    request_file: Path


def problems(robot: str, scene: str, indices, directory=None) -> list[Problem]:
    """The problems ``indices`` (1-based) of ``scene`` for ``robot``, from :func:`problem_dir`."""
    from studies.benchmarks.mbm.data import problem_dir
    d = problem_dir(robot, directory) / f"{scene}_{robot}"
    out = []
    for i in indices:
        s, r = d / f"scene{i:04d}.yaml", d / f"request{i:04d}.yaml"
        if s.is_file() and r.is_file():
            out.append(Problem(robot, scene, int(i), s, r))
    return out


def request_states(path: Path, joint_names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """A ``moveit_msgs/MotionPlanRequest``'s start (its ``start_state.joint_state``) and goal (its first
    goal's joint constraints), in the order of ``joint_names`` (rad)."""
    import yaml
    d = yaml.safe_load(Path(path).read_text())
    js = d["start_state"]["joint_state"]
    start_of = dict(zip(js["name"], js["position"]))
    goal_of = {c["joint_name"]: c["position"] for c in d["goal_constraints"][0]["joint_constraints"]}
    missing = [j for j in joint_names if j not in start_of or j not in goal_of]
    if missing:
        raise ValueError(f"{path}: no value for joint(s) {', '.join(missing)}")
    return (np.array([float(start_of[j]) for j in joint_names]), np.array([float(goal_of[j]) for j in joint_names]))


def scene_cell_of(path: Path):
    """The :class:`planning.cell.Cell` of a scene file, as ``rmt import-scene`` makes it."""
    from planning.cell.moveit import load_scene, scene_cell
    _, cell = scene_cell(load_scene(path), where=str(path))
    return cell


def import_robot(robot: str, directory=None, out_dir: Path | None = None):
    """The robot (:class:`kin.Robot`) imported from its spherized URDF and SRDF as ``rmt import-urdf
    URDF --srdf SRDF`` imports it, written as a robot file in ``out_dir`` (rmtkit's cache by default) and
    read back."""
    import kin
    from kin.native.settings import cache_dir
    from kin.urdf import import_urdf
    from studies.benchmarks.mbm.data import robot_files
    urdf, srdf = robot_files(robot, directory)
    import warnings

    from kin.urdf import UrdfWarning
    with warnings.catch_warnings():         # robowflex's placeholder inertials, the SRDF's frame-only links
        warnings.simplefilter("ignore", UrdfWarning)
        chain = import_urdf(str(urdf), tip=TIPS[robot], srdf=srdf)
    out_dir = Path(out_dir) if out_dir is not None else cache_dir() / "mbm" / "robots"
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{robot}.toml"
    kin.save_robot(chain, path)
    return kin.load_robot(path), urdf, srdf
