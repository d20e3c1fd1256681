"""Row-wise evaluation of a CasADi function in its virtual machine (the evaluators used without a C
compiler): :func:`map_rows`."""
from __future__ import annotations

from collections.abc import Iterator

import casadi as ca
import numpy as np

__all__ = ["map_rows", "CHUNK"]

#: rows evaluated by one mapped call
CHUNK = 4096


def map_rows(f: ca.Function, args: list[np.ndarray], maps: dict) -> Iterator[tuple[int, int, list[np.ndarray]]]:
    """Evaluate ``f`` on the rows of ``args`` (each (N, k_i)) in chunks of :data:`CHUNK`: yields
    (first row, rows, outputs), output j as (rows, *f's output j shape).  Mapped functions exist for
    powers of two only (a chunk is padded with its last row) and are kept in ``maps``, so that batches
    of ever-changing size (IK's active sets) reuse at most 13 of them."""
    N = len(args[0])
    for s in range(0, N, CHUNK):
        chunk = [a[s:s + CHUNK] for a in args]
        k = len(chunk[0])
        m = 1 << (k - 1).bit_length()
        if m != k:
            chunk = [np.vstack([a, np.repeat(a[-1:], m - k, axis=0)]) for a in chunk]
        key = (f.name(), m)
        if key not in maps:
            maps[key] = f.map(m, "serial")
        res = maps[key](*(a.T for a in chunk))
        res = res if isinstance(res, tuple) else (res,)
        outs = []
        for j, r in enumerate(res):
            rows, cols = f.size_out(j)
            outs.append(np.asarray(r).reshape(rows, m, cols).transpose(1, 0, 2)[:k])
        yield s, k, outs
