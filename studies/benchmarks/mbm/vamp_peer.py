"""VAMP (Thomason, Kingston, Kavraki, "Motions in Microseconds via Vectorized Sampling-Based Planning",
ICRA 2024), the record holder on MotionBenchMaker, run in the same process on the same problems: its
RRT-Connect and simplification with the settings its own ``configure_robot_and_planner_with_kwargs``
gives, on the scene as its own MotionBenchMaker loader builds it (cylinders as capsules, and as boxes in
the "box" scene — VAMP's choices), the Halton sampler its evaluation script uses.

Times: VAMP's own measurement of planning plus simplification (the nanoseconds it reports, what its
papers quote), and the wall time of the two Python calls around them (which also convert the
environment).  A peer for benchmarks only: ``import vamp`` failing leaves it out with a message.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["vamp_available", "VampPeer", "VampResult"]


def vamp_available() -> str | None:
    """None when ``import vamp`` works, else why not (with how to get it)."""
    try:
        import vamp  # noqa: F401
    except ImportError as e:
        return (f"VAMP is not installed ({e}); pip install vamp-planner (it builds from source), or a wheel built "
                "for this machine")
    return None


@dataclass(frozen=True)
class VampResult:
    valid: bool            # start and goal valid for VAMP
    solved: bool
    time_s: float          # VAMP's own planning + simplification time
    wall_s: float          # the Python calls' wall time
    length: float          # simplified path length (joint space)
    iterations: int


class VampPeer:
    """VAMP's planner for ``robot`` (``panda`` or ``ur5``)."""

    def __init__(self, robot: str, seed: int = 0):
        import vamp
        self.vamp = vamp
        self.module, self.planner, self.settings, self.simplify = vamp.configure_robot_and_planner_with_kwargs(
            robot, "rrtc")
        self.sampler = self.module.halton()
        self.n = self.module.dimension()

    def environment(self, scene_file: Path, scene_kind: str):
        import yaml
        from scipy.spatial.transform import Rotation
        vamp = self.vamp
        env = vamp.Environment()
        d = yaml.safe_load(Path(scene_file).read_text())
        for co in d["world"]["collision_objects"]:
            for prim, pose in zip(co.get("primitives", []), co.get("primitive_poses", [])):
                p = [float(x) for x in pose["position"]]
                euler = list(Rotation.from_quat(pose["orientation"]).as_euler("xyz"))
                dims = [float(x) for x in prim["dimensions"]]
                if prim["type"] == "box":
                    env.add_cuboid(vamp.Cuboid(p, euler, [x / 2 for x in dims]))
                elif prim["type"] == "cylinder":
                    if scene_kind == "box":
                        env.add_cuboid(vamp.Cuboid(p, euler, [dims[1], dims[1], dims[0] / 2]))
                    else:
                        env.add_capsule(vamp.Cylinder(p, euler, dims[1], dims[0]))
                elif prim["type"] == "sphere":
                    env.add_sphere(vamp.Sphere(p, dims[0]))
        return env

    def solve(self, scene_file: Path, scene_kind: str, start: np.ndarray, goal: np.ndarray) -> VampResult:
        env = self.environment(scene_file, scene_kind)
        s, g = [float(x) for x in start], [float(x) for x in goal]
        if not (self.module.validate(s, env) and self.module.validate(g, env)):
            return VampResult(False, False, float("nan"), float("nan"), float("nan"), 0)
        t0 = time.perf_counter()
        r = self.planner(s, g, env, self.settings, self.sampler)
        if not r.solved:
            return VampResult(True, False, r.nanoseconds * 1e-9, time.perf_counter() - t0, float("nan"),
                              int(r.iterations))
        sr = self.module.simplify(r.path, env, self.simplify, self.sampler)
        wall = time.perf_counter() - t0
        return VampResult(True, True, (r.nanoseconds + sr.nanoseconds) * 1e-9, wall, float(sr.path.cost()),
                          int(r.iterations))
