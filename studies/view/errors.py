"""What a view refuses: bad input to ``rmt view`` (its files and options) — the CLI exits with code 2."""
from __future__ import annotations

import kin

__all__ = ["ViewInputError"]


class ViewInputError(kin.RmtError):
    """Bad input to a view (a reach folder, a path or trajectory file, an option)."""
