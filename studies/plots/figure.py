"""Writing figures: matplotlib with the Agg canvas and no pyplot state (every figure is its own
``Figure``), saved as PNG atomically."""
from __future__ import annotations

import os
from pathlib import Path

from kin.output import write_output

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["save_figure"]

def save_figure(fig: Figure, path: str | os.PathLike, dpi: int | None = None) -> Path:
    """Write ``fig`` as PNG to ``path`` with :func:`kin.output.write_output` (atomic; never replaces
    anything but a regular file; missing parent directories are created)."""
    FigureCanvasAgg(fig)
    return write_output(path, lambda fh: fig.savefig(fh, format="png", dpi=dpi))
