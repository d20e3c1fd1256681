"""Figures never hide values behind matplotlib's offset notation, and a planar workspace is drawn in
one view of its plane (the views along its flat axis would be lines)."""
from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import kin
from design.workspace import compute_workspace
from studies.plots import plot_workspace
from studies.plots.figure import no_offsets, save_figure


def _offset_texts(fig):
    FigureCanvasAgg(fig).draw()
    return [ax.yaxis.get_offset_text().get_text() for ax in fig.axes]


def test_constant_joint_keeps_its_true_value(tmp_path):
    fig = Figure()
    ax = fig.add_subplot()
    ax.plot([0, 1, 2], [1000.0001, 1000.0002, 1000.0003])     # a nearly constant joint far from 0
    assert _offset_texts(fig) != [""]                         # matplotlib's default would hide 1000
    save_figure(fig, tmp_path / "f.png")
    assert _offset_texts(fig) == [""]
    labels = [t.get_text() for t in fig.axes[0].get_yticklabels() if t.get_text()]
    assert any(lab.startswith("1000.000") for lab in labels)


def test_no_offsets_covers_every_axes():
    fig = Figure()
    for k in range(3):
        fig.add_subplot(1, 3, k + 1).plot([0, 1], [5e5, 5e5 + 1e-3])
    assert _offset_texts(no_offsets(fig)) == ["", "", ""]


def test_planar_workspace_is_one_view_of_its_plane(tmp_path, monkeypatch):
    import studies.plots.workspace as pw

    ws = compute_workspace(kin.load_robot("planar_2r"), n_samples=2000, seed=0)
    assert ws.dimension == 2 and ws.degenerate_axes == ("z",)
    figs = []
    real = pw.save_figure
    monkeypatch.setattr(pw, "save_figure", lambda fig, path: (figs.append(fig), real(fig, path))[1])
    plot_workspace(ws, tmp_path / "w.png")
    [fig] = figs
    data_axes = [ax for ax in fig.axes if ax.lines]
    assert len(data_axes) == 1
    ax = data_axes[0]
    assert ax.get_xlabel() == "x (m)" and ax.get_ylabel() == "y (m)"
    x, y = np.concatenate([ln.get_xdata() for ln in ax.lines]), np.concatenate([ln.get_ydata() for ln in ax.lines])
    np.testing.assert_allclose(np.hypot(x, y).max(), ws.reach, rtol=1e-9)
    # a 3-D workspace keeps its four views
    figs.clear()
    plot_workspace(compute_workspace(kin.load_robot("scara_rrp"), n_samples=2000, seed=0), tmp_path / "s.png")
    assert len([ax for ax in figs[0].axes if ax.lines]) == 4
