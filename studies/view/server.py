"""The live scene of ``rmt view`` in viser (three.js in the browser, served over a websocket on
localhost): the robot (real shape or capsules, a checkbox for the capsules), the cell's obstacles, the
tool; joint sliders in robot file units with the live readout (:mod:`studies.view.readouts`); a handle
on the tool that solves IK as it is dragged (:mod:`studies.view.handle`); path playback with a timeline,
the swept tool trace and σ_min and clearance plotted under it (:mod:`studies.view.playback`); reach
targets that jump to their configuration when clicked (:mod:`studies.view.targets`).  The robot turns
red while it is in a window, in collision or below the σ_min floor.

viser is imported here only: ``rmt view`` loads this module when it runs."""
from __future__ import annotations

import contextlib
import io
import threading
import time

import numpy as np
import viser
import viser.transforms as vtf

from studies.view.handle import solve_handle
from studies.view.scene import (
    ALARM_RGB,
    body_poses,
    capsule_parts,
    mesh_parts,
    nearest_to_ray,
    obstacle_parts,
    slider_spec,
)

__all__ = ["ViewServer"]

#: frames per second of playback
FPS = 30


def _wxyz(T: np.ndarray) -> np.ndarray:
    return vtf.SO3.from_matrix(np.asarray(T, float)[:3, :3]).wxyz


class ViewServer:
    """The viser server of one view.  ``model``: :class:`studies.view.readouts.LiveModel`; ``q0``: the
    start (SI); ``cell_meshes``: a cell's original triangles by obstacle name; ``timeline``:
    :class:`studies.view.playback.Timeline` or None; ``study``: a reach study or None."""

    def __init__(self, model, q0, *, host: str, port: int, cell_meshes=None, timeline=None, study=None,
                 notes: list[str] | None = None):
        self.model = model
        self.chain = model.chain
        self.q = np.asarray(q0, float)
        self.timeline = timeline
        self.study = study
        self.notes = list(notes or [])
        self._lock = threading.RLock()
        self._syncing = False
        self._playing = False
        self._player = None
        self._stop = threading.Event()
        with contextlib.redirect_stdout(io.StringIO()):     # viser's banner: rmt view prints its own line
            self.server = viser.ViserServer(host=host, port=port, verbose=False)
        self.server.scene.set_up_direction("+z")
        self._place_camera()
        self._build_scene(cell_meshes)
        self._build_gui()
        self.set_q(self.q)

    @property
    def port(self) -> int:
        return int(self.server.get_port())

    def stop(self) -> None:
        self._stop.set()
        self._playing = False
        with contextlib.redirect_stdout(io.StringIO()):
            self.server.stop()

    def _place_camera(self) -> None:
        """Look at the robot from the front left, at a distance of about three times its reach."""
        from studies.view.scene import body_poses
        F = body_poses(self.model, self.q)
        centre = F[:, :3, 3].mean(axis=0)
        reach = max(float(np.ptp(F[:, :3, 3], axis=0).max()), 0.3)
        cam = self.server.initial_camera
        cam.look_at = tuple(centre)
        cam.position = tuple(centre + reach * np.array([2.2, -2.4, 1.3]))

    # ---- the scene --------------------------------------------------------------------------------
    def _build_scene(self, cell_meshes) -> None:
        sc, model = self.server.scene, self.model
        self.meshes, shape_note = mesh_parts(model.robot)
        self.notes.insert(0, shape_note)
        caps = capsule_parts(model.world) if model.world is not None else []
        with_mesh = {p.body for p in self.meshes}
        self.frames = {}
        self.robot_nodes = []          # (handle, part, is capsule)
        for b in range(self.chain.n + 2):
            self.frames[b] = sc.add_frame(f"/robot/b{b}", show_axes=False)
        for p in self.meshes + caps:
            # the capsules show where no real shape is known, and the tool's always
            visible = p.kind in ("mesh", "tool") or p.body not in with_mesh or not self.meshes
            h = sc.add_mesh_simple(f"/robot/b{p.body}/{p.name}", p.vertices, p.faces, color=p.rgb,
                                   opacity=None if p.opacity >= 1 else p.opacity, flat_shading=p.kind != "mesh",
                                   visible=visible)
            self.robot_nodes.append((h, p))
        for p in obstacle_parts(model.world, cell_meshes) if model.world is not None else []:
            sc.add_mesh_simple(f"/cell/{p.name}", p.vertices, p.faces, color=p.rgb, opacity=p.opacity,
                               flat_shading=True)
        sc.add_grid("/cell/floor grid", width=4.0, height=4.0, cell_size=0.1, section_size=0.5,
                    position=(0.0, 0.0, float(model.base[2, 3]) if model.world is not None and
                              not model.world.obstacles else 0.0))
        T = model.tool_pose(self.q)
        self.handle = sc.add_transform_controls("/tool handle", scale=0.15, wxyz=_wxyz(T), position=T[:3, 3])
        self._dragging = False
        self.handle.on_update(self._on_handle)
        if self.timeline is not None:
            trace = self.timeline.tool_trace(model)
            seg = np.stack([trace[:-1], trace[1:]], axis=1) if len(trace) > 1 else np.zeros((0, 2, 3))
            if len(seg):
                sc.add_line_segments("/path/tool trace", seg, colors=(255, 127, 14), thickness=4.0,
                                     thickness_units="screen")
        if self.study is not None:
            self._add_targets()

    def _add_targets(self) -> None:
        from studies.report.cell_view import _icosahedron
        from studies.view.targets import target_colours
        V, F = _icosahedron()
        P = np.asarray(self.study.positions, float)
        self._target_colour_by = {by: target_colours(self.study, by) for by in ("score", "reason")}
        self.targets = self.server.scene.add_batched_meshes_simple(
            "/reach/targets", V * 0.008, F, np.tile([1.0, 0, 0, 0], (len(P), 1)), P,
            batched_colors=self._target_colour_by["score"])

        @self.targets.on_click
        def _(event):
            i = event.instance_index
            if i is None:
                i = nearest_to_ray(P, event.ray_origin, event.ray_direction)
            self.jump_to_target(int(i))

    # ---- the panel --------------------------------------------------------------------------------
    def _build_gui(self) -> None:
        gui = self.server.gui
        gui.add_markdown("**rmt view** — " + self.chain.name)
        self.readout = gui.add_markdown("…")
        self.capsules = gui.add_checkbox("capsules", initial_value=not self.meshes)

        @self.capsules.on_update
        def _(_event):
            with_mesh = {p.body for p in self.meshes}
            for h, p in self.robot_nodes:
                if p.kind == "capsules" and p.body in with_mesh:
                    h.visible = bool(self.capsules.value)
        with gui.add_folder("joints"):
            self.sliders = []
            qf = self.chain.from_si(self.q)
            for j, spec in enumerate(slider_spec(self.chain)):
                s = gui.add_slider(spec["label"], min=spec["min"], max=spec["max"], step=spec["step"],
                                   initial_value=float(np.clip(qf[j], spec["min"], spec["max"])))
                s.on_update(self._on_slider)
                self.sliders.append(s)
        if self.timeline is not None:
            self._build_playback()
        if self.study is not None:
            self._build_targets_gui()
        for text in self.notes:
            gui.add_markdown(f"*{text}*")

    def _build_playback(self) -> None:
        gui, tl = self.server.gui, self.timeline
        with gui.add_folder("playback"):
            lo, hi = float(tl.t[0]), float(tl.t[-1])
            self.time_slider = gui.add_slider(f"timeline [{'s' if tl.timed else 'path'}]", min=lo,
                                              max=hi if hi > lo else lo + 1e-9, step=max((hi - lo) / 1000, 1e-6),
                                              initial_value=lo)
            self.play = gui.add_button("play")
            self.time_slider.on_update(lambda _e: None if self._syncing else self.set_q(tl.at(self.time_slider.value)))
            self.play.on_click(lambda _e: self.toggle_play())
            from studies.view.plot import profile_figure
            gui.add_plotly(profile_figure(self.model, tl), aspect=1.8)

    def _build_targets_gui(self) -> None:
        from studies.view.targets import target_label
        gui, c = self.server.gui, self.chain
        with gui.add_folder("reach targets"):
            colour = gui.add_dropdown("colour by", ("score", "reason"), initial_value="score")

            @colour.on_update
            def _(_e):
                self.targets.batched_colors = self._target_colour_by[colour.value]
            labels = [target_label(self.study, i, c.length_scale, c.length_unit) for i in range(len(self.study))]
            self._target_labels = labels
            pick = gui.add_dropdown("jump to", labels, initial_value=labels[0])
            pick.on_update(lambda _e: self.jump_to_target(labels.index(pick.value)))

    # ---- updates ----------------------------------------------------------------------------------
    def jump_to_target(self, i: int) -> None:
        self.set_q(self.study.q[i], note=self._target_labels[i] if hasattr(self, "_target_labels") else "")

    def _on_slider(self, _event) -> None:
        if self._syncing:
            return
        self.set_q(self.chain.to_si(np.array([float(s.value) for s in self.sliders])))

    def _on_handle(self, _event) -> None:
        if self._syncing:
            return
        T = np.eye(4)
        T[:3, :3] = vtf.SO3(np.asarray(self.handle.wxyz, float)).as_matrix()
        T[:3, 3] = np.asarray(self.handle.position, float)
        with self._lock:
            ans = solve_handle(self.model, T, self.q)
        if ans.q is None:
            self._show(self.model.readout(self.q), extra=ans.text)
            return
        self.set_q(ans.q, move_handle=False, note=ans.text)

    def set_q(self, q, move_handle: bool = True, note: str = "") -> None:
        """Show configuration ``q`` (SI): bodies, sliders, handle, readout, colours."""
        with self._lock:
            self.q = np.asarray(q, float)
            r = self.model.readout(self.q)
            F = body_poses(self.model, self.q)
            with self.server.atomic():
                for b, h in self.frames.items():
                    h.wxyz, h.position = _wxyz(F[b]), F[b][:3, 3]
                self._syncing = True
                try:
                    qf = self.chain.from_si(self.q)
                    for s, v in zip(self.sliders, qf):
                        if abs(float(s.value) - v) > 1e-12:
                            s.value = float(np.clip(v, s.min, s.max))
                    if move_handle:
                        T = r.pose
                        self.handle.wxyz, self.handle.position = _wxyz(T), T[:3, 3]
                finally:
                    self._syncing = False
                for h, p in self.robot_nodes:
                    h.color = ALARM_RGB if r.alarm and p.kind != "tool" else p.rgb
            self._show(r, extra=note)

    def _show(self, r, extra: str = "") -> None:
        lines = self.model.lines(r) + ([extra] if extra else [])
        self.last_lines = lines
        self.readout.content = "\n".join(f"- {line}" for line in lines)

    def toggle_play(self) -> None:
        if self._playing:
            self._playing = False
            if self._player is not None:
                self._player.join(timeout=2.0)
            self.play.label = "play"
            return
        self._playing = True
        self.play.label = "pause"
        self._player = threading.Thread(target=self._run_playback, daemon=True)
        self._player.start()

    def _run_playback(self) -> None:
        tl = self.timeline
        speed = tl.playback_speed()
        s = float(self.time_slider.value)
        if s >= tl.t[-1]:
            s = float(tl.t[0])
        last = time.monotonic()
        while self._playing and not self._stop.is_set():
            time.sleep(1 / FPS)
            now = time.monotonic()
            s = min(s + (now - last) * speed, float(tl.t[-1]))
            last = now
            with self._lock:
                if not self._playing:
                    break
                self._syncing = True
                try:
                    self.time_slider.value = s
                finally:
                    self._syncing = False
                self.set_q(tl.at(s))
            if s >= tl.t[-1]:
                break
        self._playing = False
        self.play.label = "play"
