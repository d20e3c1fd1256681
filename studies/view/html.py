"""The scene of ``rmt view`` as one self-contained HTML file (``rmt view --html OUT.html``).

The page holds plotly.js inline (no request to any network, as the reports' 3-D views), the cell's
obstacles, the robot — its real shape where known (:func:`studies.shape.meshes.visual_meshes`), else
its capsules — the closest approach at the start, a joint path or trajectory animated along a slider
(:func:`studies.report.cell_view.cell_view`), reach targets as markers, and a joint slider per joint
in the robot file's units: moving one places every body again in the page (the robot file's DH
forward kinematics, in JavaScript) and updates the tool-pose readout.  Clearances and σ_min are
live only in ``rmt view``'s server: the page shows the closest approach of the drawn configuration
and hides it once a slider moves.
"""
from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

__all__ = ["view_html", "write_view_html"]


def _payload(robot, world, parts, q0) -> dict:
    """What the page's forward kinematics needs: DH rows (SI), placements, each drawn vertex in its
    body's frame and its body, the sliders (file units)."""
    from kin.geometry.frames import dh_rows

    chain = robot.chain
    a_s, l_s = chain.angle_scale, chain.length_scale
    sliders = []
    for k, j in enumerate(chain.joints):
        s = a_s if j.is_revolute else l_s
        sliders.append({"label": j.name or f"joint {k + 1}", "lo": j.limits[0] / s, "hi": j.limits[1] / s,
                        "value": float(q0[k]) / s, "scale": s,
                        "unit": chain.angle_unit if j.is_revolute else chain.length_unit})
    return {"rows": dh_rows(chain).tolist(), "modified": chain.convention == "modified",
            "base": (np.asarray(world.base) @ chain.base.matrix).tolist(), "tool": chain.tool.matrix.tolist(),
            "scale": l_s, "unit": chain.length_unit, "angle_scale": a_s, "angle_unit": chain.angle_unit,
            "decimals": 6, "sliders": sliders,
            "parts": [{"v": np.round(V, 7).tolist(), "body": body.tolist()} for V, _, body in parts]}


def view_html(robot, world=None, *, q=None, path=None, times=None, cell_meshes=None, points=(), title: str = "",
              shape="auto") -> str:
    """The page's text (see the module docstring); ``world`` a :class:`planning.collision.CollisionWorld`
    (default: the robot alone), ``q`` the start (SI; default the path's first row or zero), ``path``
    (M, n) SI, ``times`` (M,) s of a trajectory (its duration is stated), ``points`` markers
    as :func:`~studies.report.cell_view.cell_view` takes them."""
    import plotly.offline

    from planning.collision import CollisionWorld
    from studies.report.cell_view import SHAPE_BUDGET, cell_view, robot_parts
    from studies.report.html import figure_json
    from studies.shape.meshes import visual_meshes

    chain = robot.chain
    world = world if world is not None else CollisionWorld(robot)
    if isinstance(shape, str):
        shape = visual_meshes(robot, budget=SHAPE_BUDGET) if shape == "auto" else None
    Q = None if path is None else np.asarray(path, float)
    q0 = np.asarray(q, float) if q is not None else (Q[0] if Q is not None else np.zeros(chain.n))
    title = title or f"{chain.title or chain.name}{' in ' + world.name if world.name else ''}"
    fig = cell_view(world, q0, path=Q, meshes=cell_meshes, title="", closest="all", points=points, shape=shape)
    n = chain.n
    parts = [robot_parts(world.geometry, set(range(n + 1)), shape), robot_parts(world.geometry, {n + 1}, shape)]
    figure = figure_json(fig)
    model = json.dumps(_payload(robot, world, parts, q0), allow_nan=False).replace("</", "<\\/")
    drawn = "its meshes" if shape else "its collision capsules"
    timed = "" if times is None or len(times) < 2 else f" The trajectory lasts {float(times[-1] - times[0]):.3f} s."
    return "\n".join([
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style>",
        f"<script>{plotly.offline.get_plotlyjs()}</script></head><body>",
        f'<header><h1>{html.escape(title)}</h1><p>{html.escape(chain.name)} drawn as {drawn}; lengths in '
        f'{html.escape(chain.length_unit)}, angles in {html.escape(chain.angle_unit)}. Written by rmt view --html.'
        f'{timed}</p></header>',
        '<div id="wrap"><div id="scene"></div><aside><h2>Joints</h2><div id="sliders"></div>'
        '<h2>Tool</h2><pre id="readout"></pre></aside></div>',
        f'<script type="application/json" id="figure">{figure}</script>',
        f'<script type="application/json" id="model">{model}</script>',
        f"<script>{_JS}</script></body></html>"])


def write_view_html(robot, world=None, path=None, trajectory=None, reach=None, out=None, *, q=None,
                    cell_meshes=None, title: str = "") -> Path:
    """Write :func:`view_html` to ``out`` (:func:`kin.output.write_output`); ``trajectory``: (times,
    Q) of a timed trajectory (instead of ``path``); ``reach``: markers, (name, positions (K, 3) world
    m, colour) each."""
    from kin.output import write_output

    times = None
    if trajectory is not None:
        times, path = trajectory
    text = view_html(robot, world, q=q, path=path, times=times, cell_meshes=cell_meshes, points=tuple(reach or ()),
                     title=title)
    return write_output(out, text)


_STYLE = """
body{font-family:system-ui,sans-serif;margin:0;color:#222}header{padding:6px 14px}h1{font-size:1.2em;margin:4px 0}
header p{margin:2px 0;color:#555;font-size:.9em}#wrap{display:flex;height:calc(100vh - 70px)}
#scene{flex:1;min-width:0}aside{width:300px;padding:0 12px;overflow-y:auto;border-left:1px solid #ddd}
aside h2{font-size:1em;margin:10px 0 4px}.joint{margin:4px 0}.joint label{display:flex;justify-content:space-between;
font-size:.85em}.joint input{width:100%}pre{font-size:.85em;background:#f6f6f6;padding:6px}
"""

_JS = r"""
(function(){
const fig = JSON.parse(document.getElementById('figure').textContent);
const M = JSON.parse(document.getElementById('model').textContent);
const el = document.getElementById('scene');
const mul = (A, B) => A.map((r, i) => B[0].map((_, j) => r.reduce((s, _, k) => s + A[i][k] * B[k][j], 0)));
function dh(row, q) {
  let [a, al, d, th, pris] = row;
  if (pris) d += q; else th += q;
  const ct = Math.cos(th), st = Math.sin(th), ca = Math.cos(al), sa = Math.sin(al);
  if (M.modified) return [[ct, -st, 0, a], [st*ca, ct*ca, -sa, -sa*d], [st*sa, ct*sa, ca, ca*d], [0, 0, 0, 1]];
  return [[ct, -st*ca, st*sa, a*ct], [st, ct*ca, -ct*sa, a*st], [0, sa, ca, d], [0, 0, 0, 1]];
}
function frames(q) {
  const F = [M.base];
  M.rows.forEach((row, k) => F.push(mul(F[k], dh(row, q[k]))));
  F.push(mul(F[F.length - 1], M.tool));
  return F;
}
function place(part, F) {
  const x = [], y = [], z = [], s = M.scale;
  part.v.forEach((v, i) => { const T = F[part.body[i]];
    x.push((T[0][0]*v[0] + T[0][1]*v[1] + T[0][2]*v[2] + T[0][3]) / s);
    y.push((T[1][0]*v[0] + T[1][1]*v[1] + T[1][2]*v[2] + T[1][3]) / s);
    z.push((T[2][0]*v[0] + T[2][1]*v[1] + T[2][2]*v[2] + T[2][3]) / s); });
  return [x, y, z];
}
function rpy(R) {      // fixed-axis roll, pitch, yaw (as rmt fk prints them)
  const p = Math.atan2(-R[2][0], Math.hypot(R[0][0], R[1][0]));
  return [Math.atan2(R[2][1], R[2][2]), p, Math.atan2(R[1][0], R[0][0])];
}
function readout(F) {
  const T = F[F.length - 1], d = M.decimals, r = rpy(T).map(a => a / M.angle_scale);
  document.getElementById('readout').textContent =
    'xyz (' + M.unit + '): ' + [0, 1, 2].map(i => (T[i][3] / M.scale).toFixed(d)).join(' ') + '\n' +
    'rpy (' + M.angle_unit + '): ' + r.map(a => a.toFixed(d)).join(' ');
}
const box = document.getElementById('sliders'), inputs = [];
M.sliders.forEach((s, k) => {
  const div = document.createElement('div'); div.className = 'joint';
  const lab = document.createElement('label'), name = document.createElement('span');
  const val = document.createElement('span');
  name.textContent = s.label; val.className = 'value'; lab.append(name, val);
  const inp = document.createElement('input');
  Object.assign(inp, {type: 'range', min: s.lo, max: s.hi, step: 'any', value: s.value});
  inp.dataset.joint = k; div.append(lab, inp); box.append(div); inputs.push([inp, val, s]);
});
function update(move) {
  const q = inputs.map(([inp, val, s]) => { val.textContent = (+inp.value).toFixed(3) + ' ' + s.unit;
                                            return +inp.value * s.scale; });
  const F = frames(q);
  readout(F);
  if (!move) return;
  const [a, b] = M.parts.map(p => place(p, F));
  const o = F.map(T => T.map(r => r[3] / M.scale));
  Plotly.restyle(el, {x: [a[0], b[0], o.map(p => p[0])], y: [a[1], b[1], o.map(p => p[1])],
                      z: [a[2], b[2], o.map(p => p[2])]}, [0, 1, 2]);
  if (fig.data.length > 3 && fig.data[3].mode === 'lines+markers+text') Plotly.restyle(el, {visible: false}, [3]);
  document.body.dataset.moved = '1';
}
inputs.forEach(([inp]) => inp.addEventListener('input', () => update(true)));
Plotly.newPlot(el, fig.data, fig.layout, {responsive: true, displaylogo: false}).then(() => {
  if (fig.frames && fig.frames.length) Plotly.addFrames(el, fig.frames);
  update(false);
  document.body.dataset.ready = '1';
});
})();
"""
