"""The interactive 3-D view of a report (plotly): the robot drawn as links and joint frames at a chosen
configuration, the sampled workspace with its near-singular points in red, and a joint path animated
along a slider over its waypoints.

Lengths are shown in the robot file's length unit.  The robot is drawn from the DH frames of
:attr:`kin.symbolic.SymbolicChain.frames_function` (base, every joint frame, tool), so what is drawn
is what the kinematics computes.
"""
from __future__ import annotations

import numpy as np

import kin
from studies.jointpath import densify

__all__ = ["robot_view", "frame_origins", "MAX_CLOUD_POINTS", "MAX_ANIMATION_FRAMES"]

#: at most this many workspace samples are drawn (uniform random subset, seed 0)
MAX_CLOUD_POINTS = 12_000
#: the path is animated in this many frames: a longer path is subsampled (its first and last waypoints
#: kept), a shorter one is interpolated linearly in joint space (as its segments are executed)
MAX_ANIMATION_FRAMES = 60
#: the tool's trace is drawn through this many configurations along the joint path
DENSE_POINTS = 240
_AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")        # x red, y green, z blue (the usual RGB frames)


def frame_step(label: str) -> dict:
    """The slider step that shows the animation frame named ``label``."""
    return dict(method="animate", label=label,
                args=[[label], dict(mode="immediate", frame=dict(duration=0, redraw=True),
                                    transition=dict(duration=0))])


def add_path_controls(fig, steps: list[dict], active: int = 0) -> None:
    """A slider over the frames (``steps`` from :func:`frame_step`, starting at ``active``) and a play button."""
    fig.update_layout(
        sliders=[dict(active=active, steps=steps, currentvalue=dict(prefix="along the path (%): "), pad=dict(t=30),
                      x=0.08, len=0.9)],
        updatemenus=[dict(type="buttons", showactive=False, x=0.0, y=0.0, xanchor="left", yanchor="top",
                          pad=dict(t=30),
                          buttons=[dict(label="▶ play", method="animate",
                                        args=[None, dict(frame=dict(duration=120, redraw=True), fromcurrent=True,
                                                         transition=dict(duration=0))])])])


def _frames(robot: kin.Robot, q: np.ndarray) -> np.ndarray:
    """(n+2, 4, 4): base, joint frames 1…n, tool (SI)."""
    F, T = robot.symbolic.frames_function(np.asarray(q, float), robot.chain.parameter_values)
    F = np.array(F)
    n = F.shape[1] // 4
    return np.concatenate([np.stack([F[:, 4 * i:4 * i + 4] for i in range(n)]), np.array(T)[None]])


def frame_origins(robot: kin.Robot, q) -> np.ndarray:
    """(n+2, 3) origins of the base, the joint frames and the tool, in the robot file's length unit."""
    return _frames(robot, q)[:, :3, 3] / robot.chain.length_scale


def _robot_traces(robot: kin.Robot, q: np.ndarray, axis_len: float) -> list[dict]:
    import plotly.graph_objects as go

    F = _frames(robot, q)
    s = robot.chain.length_scale
    P = F[:, :3, 3] / s
    traces = [go.Scatter3d(x=P[:, 0], y=P[:, 1], z=P[:, 2], mode="lines+markers", name="links",
                           line=dict(color="#333333", width=9), marker=dict(size=4, color="#333333"),
                           hovertemplate="frame %{text}<extra></extra>",
                           text=["base"] + [str(i) for i in range(1, len(P) - 1)] + ["tool"])]
    for k in range(3):                       # one trace per axis colour, segments separated by None
        xs, ys, zs = [], [], []
        for Fi in F:
            o, e = Fi[:3, 3] / s, Fi[:3, k]
            for arr, a, b in ((xs, o[0], e[0]), (ys, o[1], e[1]), (zs, o[2], e[2])):
                arr += [a, a + axis_len * b, None]
        traces.append(go.Scatter3d(x=xs, y=ys, z=zs, mode="lines", name=f"frame {'xyz'[k]} axes",
                                   line=dict(color=_AXIS_COLOURS[k], width=4), hoverinfo="skip"))
    return traces


def robot_view(robot: kin.Robot, q, *, cloud: np.ndarray | None = None, near_singular: np.ndarray | None = None,
               path: np.ndarray | None = None, targets: np.ndarray | None = None, title: str = "",
               cloud_seed: int = 0):
    """A plotly figure: the robot at ``q`` (SI joint values), optionally the workspace ``cloud``
    ((N, 3) tool positions in metres) with ``near_singular`` (N,) marked red, and a joint ``path``
    ((M, n), SI) drawn as the tool's trace and animated with a slider over its waypoints, and task
    ``targets`` ((K, 3) tool positions in metres) as markers."""
    import plotly.graph_objects as go

    chain = robot.chain
    s = chain.length_scale
    unit = chain.length_unit
    q = np.asarray(q, float)
    pts = [frame_origins(robot, q)]
    data = []
    if cloud is not None:
        C = np.asarray(cloud, float) / s
        near = np.zeros(len(C), bool) if near_singular is None else np.asarray(near_singular, bool)
        if len(C) > MAX_CLOUD_POINTS:
            idx = np.sort(np.random.default_rng(cloud_seed).choice(len(C), MAX_CLOUD_POINTS, replace=False))
            C, near = C[idx], near[idx]
        pts.append(C)
        data.append(go.Scatter3d(x=C[~near, 0], y=C[~near, 1], z=C[~near, 2], mode="markers",
                                 name=f"workspace ({(~near).sum():,} drawn)", hoverinfo="skip",
                                 marker=dict(size=1.6, color="#4c6a8a", opacity=0.25)))
        data.append(go.Scatter3d(x=C[near, 0], y=C[near, 1], z=C[near, 2], mode="markers",
                                 name=f"near-singular ({near.sum():,} drawn)", hoverinfo="skip",
                                 marker=dict(size=2.2, color="#d62728", opacity=0.6)))
    if targets is not None:
        P = np.asarray(targets, float).reshape(-1, 3) / s
        pts.append(P)
        data.append(go.Scatter3d(x=P[:, 0], y=P[:, 1], z=P[:, 2], mode="markers", name=f"task targets ({len(P)})",
                                 marker=dict(size=4, color="#2ca02c", symbol="diamond"),
                                 hovertemplate=f"%{{x:.4g}}, %{{y:.4g}}, %{{z:.4g}} {unit}<extra>target</extra>"))
    frames = []
    steps = []
    if path is not None and len(path):
        Q = np.asarray(path, float)
        dense = densify(Q, DENSE_POINTS)
        tool = np.array([frame_origins(robot, qk)[-1] for qk in dense])
        pts.append(tool)
        data.append(go.Scatter3d(x=tool[:, 0], y=tool[:, 1], z=tool[:, 2], mode="lines", name="planned tool path",
                                 line=dict(color="#ff7f0e", width=5), hoverinfo="skip"))
        anim = densify(Q, MAX_ANIMATION_FRAMES) if len(Q) < MAX_ANIMATION_FRAMES else \
            Q[np.unique(np.round(np.linspace(0, len(Q) - 1, MAX_ANIMATION_FRAMES)).astype(int))]
        q = Q[0]
    span = float(np.ptp(np.concatenate(pts), axis=0).max()) or 1.0
    axis_len = 0.08 * span
    robot_traces = _robot_traces(robot, q, axis_len)
    data = robot_traces + data                 # robot first: the animation frames replace traces 0..3
    if path is not None and len(path):
        for k, qk in enumerate(anim):
            name = f"{100 * k / (len(anim) - 1):.0f}" if len(anim) > 1 else "0"
            frames.append(go.Frame(name=name, data=_robot_traces(robot, qk, axis_len),
                                   traces=list(range(len(robot_traces)))))
            steps.append(frame_step(name))
    fig = go.Figure(data=data, frames=frames)
    ax = dict(title=f"{{}} ({unit})")
    fig.update_layout(
        title=title or None, margin=dict(l=0, r=0, t=40 if title else 10, b=0),
        legend=dict(itemsizing="constant", x=0.01, y=0.99),
        scene=dict(aspectmode="data", xaxis=dict(title=ax["title"].format("x")),
                   yaxis=dict(title=ax["title"].format("y")), zaxis=dict(title=ax["title"].format("z"))),
    )
    if frames:
        add_path_controls(fig, steps)
    return fig
