"""A trajectory as a ROS 2 ``trajectory_msgs/msg/JointTrajectory``: YAML (what ``ros2 topic pub``
and a launch file's parameters take) or JSON (rosbridge), with ROS's units (REP 103: rad, m, rad/s,
m/s, rad/s², m/s²).

``header.stamp`` is zero (the receiver starts the trajectory when it arrives) and ``frame_id`` the
robot's base frame; ``time_from_start`` is ``{sec, nanosec}`` rounded to the nanosecond;
``effort`` is empty (a JointTrajectory's effort is a command a position-controlled arm ignores).
"""
from __future__ import annotations

import json

import numpy as np

__all__ = ["message", "yaml_text", "json_text", "duration_msg"]


def duration_msg(t: float) -> dict[str, int]:
    """A time in s ≥ 0 as ``builtin_interfaces/Duration`` {sec, nanosec}, rounded to the nanosecond."""
    ns = int(round(t * 1e9))
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def message(names: list[str], frame_id: str, times: np.ndarray, q: np.ndarray, qd: np.ndarray,
            qdd: np.ndarray) -> dict:
    """The message as plain Python: ``times`` (T,) s; ``q``, ``qd``, ``qdd`` (T, n) SI, in the order of
    ``names``."""
    points = [{"positions": [float(x) for x in q[k]], "velocities": [float(x) for x in qd[k]],
               "accelerations": [float(x) for x in qdd[k]], "effort": [],
               "time_from_start": duration_msg(float(times[k]))} for k in range(len(times))]
    return {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": frame_id},
            "joint_names": list(names), "points": points}


def _comments(lines: list[str], mark: str) -> str:
    return "".join(f"{mark} {line}\n" for line in lines)


def yaml_text(msg: dict, notes: list[str]) -> str:
    """The message as YAML (PyYAML's safe emitter; names quoted as it needs), ``notes`` as ``#`` lines above."""
    import yaml
    body = yaml.safe_dump(msg, sort_keys=False, default_flow_style=None, allow_unicode=False, width=1 << 30)
    return _comments(notes, "#") + body


def json_text(msg: dict, notes: list[str]) -> str:
    """The message as one JSON object; ``notes`` go in a ``"_comment"`` list (JSON has no comments)."""
    return json.dumps({"_comment": notes, **msg}, allow_nan=False) + "\n"
