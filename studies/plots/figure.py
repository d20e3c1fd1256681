"""Writing figures: matplotlib with the Agg canvas and no pyplot state (every figure is its own
``Figure``), saved as PNG atomically."""
from __future__ import annotations

import os
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from kin.output import write_output

__all__ = ["save_figure", "png_bytes", "no_offsets"]


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

def png_bytes(fig: Figure, dpi: int | None = None) -> bytes:
    """``fig`` rendered as PNG (Agg canvas, offset notation off)."""
    import io

    FigureCanvasAgg(fig)
    no_offsets(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def save_figure(fig: Figure, path: str | os.PathLike, dpi: int | None = None) -> Path:
    """Write ``fig`` as PNG (:func:`png_bytes`) to ``path`` with :func:`kin.output.write_output`
    (atomic; never replaces anything but a regular file; missing parent directories are created)."""
    return write_output(path, png_bytes(fig, dpi))
