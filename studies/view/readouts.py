"""The live values of ``rmt view``: for one configuration, the tool pose (the cell frame with a cell,
else the robot's base placement frame; robot file units), σ_min (SI), the nearest obstacle and the
nearest self pair with their clearance (:class:`planning.collision.ClearanceTally`, as ``rmt
clearance`` names them), whether the configuration lies inside a singular window
(:class:`planning.windows.WindowSet`, as ``rmt plan --margin/--sigma-min`` builds them) or below the
σ_min floor, and whether it is in collision.  No viser here: :class:`LiveModel` is plain numpy, and
what the browser shows is :meth:`Readout.lines`."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from kin.transforms import matrix_to_rpy

__all__ = ["LiveModel", "Readout"]


@dataclass(frozen=True)
class Readout:
    """What the viewer shows for one configuration ``q`` (SI).  ``pose``: the tool frame in the world
    (4×4, m; the cell frame with a cell); ``clearance``: the smallest signed distance the world checks
    (m; None without a world); ``obstacle``/``self_pair``: :class:`planning.collision.Nearest` or None;
    ``windows``: the names of the windows holding ``q``."""

    q: np.ndarray
    pose: np.ndarray
    sigma_min: float
    clearance: float | None
    in_collision: bool
    obstacle: object | None
    self_pair: object | None
    windows: tuple[str, ...]
    below_floor: bool
    within_limits: bool
    notes: tuple[str, ...] = field(default=())

    @property
    def alarm(self) -> bool:
        """Whether the robot is drawn red: in a window, in collision or below the σ_min floor."""
        return bool(self.windows) or self.in_collision or self.below_floor


def _num(v: float) -> str:
    """Six significant digits; rounding noise below 1e-9 of the unit shown as 0."""
    return f"{v:.6g}" if abs(v) >= 1e-9 else "0"


class LiveModel:
    """The robot (``robot``, with its tool centre point), its :class:`planning.collision.CollisionWorld`
    (``world``: the cell and the robot itself; its ``base`` places the robot), the windows (a
    :class:`planning.windows.WindowSet` or None) and the σ_min floor (SI, None: off; ``floor_text`` its
    words).  ``frame``: what the pose readout calls its frame."""

    def __init__(self, robot, world, windows=None, floor: float | None = None, floor_text: str = "off",
                 frame: str = "base frame"):
        self.robot = robot
        self.chain = robot.chain
        self.world = world
        self.windows = windows
        self.floor = floor
        self.floor_text = floor_text
        self.frame = frame
        self.base = np.eye(4) if world is None else np.asarray(world.base, float)
        self._checker = None

    # ---- values -----------------------------------------------------------------------------------
    def tool_pose(self, q) -> np.ndarray:
        """The tool frame in the world (4×4, m): the robot's placement · its forward kinematics."""
        return self.base @ np.asarray(self.robot.fk(np.asarray(q, float)), float)

    def window_names(self, Q) -> list[tuple[str, ...]]:
        """Per configuration of ``Q`` (N, n; SI), the names of the windows that hold it."""
        Q = np.atleast_2d(np.asarray(Q, float))
        if self.windows is None or not self.windows.windows:
            return [()] * len(Q)
        M = self.windows.membership(Q)
        names = [w.name for w in self.windows.windows]
        return [tuple(names[j] for j in np.flatnonzero(row)) for row in M]

    def readout(self, q) -> Readout:
        q = np.asarray(q, float).reshape(-1)
        s = float(self.robot.sigma_min(q))
        clearance, obstacle, self_pair, hit = None, None, None, False
        if self.world is not None:
            from planning.collision import ClearanceTally
            tally = ClearanceTally(self.world)
            clearance = float(tally.add(q[None])[0])
            obstacle, self_pair = tally.obstacle, tally.self_pair
            hit = not clearance > self.world.margin
        return Readout(q=q, pose=self.tool_pose(q), sigma_min=s, clearance=clearance, in_collision=hit,
                       obstacle=obstacle, self_pair=self_pair, windows=self.window_names(q)[0],
                       below_floor=self.floor is not None and s < self.floor,
                       within_limits=bool(self.chain.within_limits(q)))

    def profile(self, Q) -> dict:
        """Along configurations ``Q`` (N, n; SI): σ_min (N,), the clearance (N,; m, NaN without a world)
        and whether each lies in a window (N,) — what the timeline's plot shows."""
        Q = np.atleast_2d(np.asarray(Q, float))
        sig = np.asarray(self.robot.sigma_min(Q), float).reshape(-1)
        clear = np.full(len(Q), np.nan) if self.world is None else np.asarray(self.world.clearance(Q), float)
        inside = np.array([bool(w) for w in self.window_names(Q)])
        return {"sigma_min": sig, "clearance": clear, "in_window": inside}

    def checker(self):
        """The :class:`planning.ompl.validity.JointSpaceChecker` of this view (limits, windows, floor,
        collisions), built on first use: the tool handle's IK chooses among valid branches with it."""
        if self._checker is None:
            from planning.ompl.validity import JointSpaceChecker
            self._checker = JointSpaceChecker(self.robot, self.windows, self.floor, world=self.world)
        return self._checker

    # ---- words ------------------------------------------------------------------------------------
    def lines(self, r: Readout) -> list[str]:
        """The readout in words: robot file units for the pose, SI for σ_min, mm for clearances."""
        c = self.chain
        xyz = r.pose[:3, 3] / c.length_scale
        rpy = np.asarray(matrix_to_rpy(r.pose[:3, :3]), float) / c.angle_scale
        out = [f"tool ({self.frame}, {c.length_unit}): x {_num(xyz[0])}  y {_num(xyz[1])}  z {_num(xyz[2])}",
               f"tool roll-pitch-yaw ({c.angle_unit}): {_num(rpy[0])}  {_num(rpy[1])}  {_num(rpy[2])}",
               f"σ_min: {r.sigma_min:.4g} (SI)" + (f" — below the floor ({self.floor_text})" if r.below_floor
                                                   else f"; floor: {self.floor_text}")]
        if self.world is not None:
            cap = f"≥ {self.world.cap * 1e3:.0f} mm"
            if not self.world.obstacles:
                out.append("nearest obstacle: none (no cell)")
            else:
                out.append(r.obstacle.text(row="") if r.obstacle is not None else f"nearest obstacle: {cap}")
            out.append(r.self_pair.text(row="") if r.self_pair is not None else f"nearest self pair: {cap}")
            state = "IN COLLISION" if r.in_collision else "clear"
            out.append(f"clearance: {r.clearance * 1e3:.4g} mm — {state}"
                       + (f" (required {self.world.margin * 1e3:.4g} mm)" if self.world.margin else ""))
        if self.windows is None:
            out.append("windows: none built (--margin X or --sigma-min S gives them)")
        elif r.windows:
            out.append("IN WINDOW " + ", ".join(f"'{w}'" for w in r.windows))
        else:
            out.append(f"outside all {len(self.windows.windows)} windows")
        if not r.within_limits:
            out.append("outside the joint limits")
        return out + list(r.notes)

    def to_dict(self, r: Readout) -> dict:
        """The readout as JSON-ready values: the pose in robot file units, σ_min SI, clearances in m."""
        c = self.chain
        return {"q": c.from_si(r.q).tolist(), "position": (r.pose[:3, 3] / c.length_scale).tolist(),
                "rpy": (np.asarray(matrix_to_rpy(r.pose[:3, :3]), float) / c.angle_scale).tolist(),
                "frame": self.frame, "sigma_min": r.sigma_min, "clearance_m": r.clearance,
                "in_collision": r.in_collision, "windows": list(r.windows), "below_floor": r.below_floor,
                "nearest_obstacle": None if r.obstacle is None else r.obstacle.to_dict(),
                "nearest_self": None if r.self_pair is None else r.self_pair.to_dict(), "alarm": r.alarm}
