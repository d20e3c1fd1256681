"""Writing figures: matplotlib with the Agg canvas and no pyplot state (every figure is its own
``Figure``), saved as PNG atomically."""
from __future__ import annotations

import os
from pathlib import Path

from kin.output import write_output

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["save_figure", "no_offsets"]


def no_offsets(fig: Figure) -> Figure:
    """Turn off matplotlib's offset notation (``1e3 + …`` beside an axis) on every axis of ``fig``: a
    joint held constant, or values far from zero, keep their true tick labels."""
    from matplotlib.ticker import ScalarFormatter

    for ax in fig.axes:
        for axis in (getattr(ax, name, None) for name in ("xaxis", "yaxis", "zaxis")):
            fmt = axis.get_major_formatter() if axis is not None else None
            if isinstance(fmt, ScalarFormatter):
                fmt.set_useOffset(False)
    return fig

def save_figure(fig: Figure, path: str | os.PathLike, dpi: int | None = None) -> Path:
    """Write ``fig`` as PNG to ``path`` with :func:`kin.output.write_output` (atomic; never replaces
    anything but a regular file; missing parent directories are created)."""
    FigureCanvasAgg(fig)
    no_offsets(fig)
    return write_output(path, lambda fh: fig.savefig(fh, format="png", dpi=dpi))
