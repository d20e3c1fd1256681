"""Strict JSON for everything rmtkit writes: ``--json`` output, ``results.json`` and benchmark figures.

JSON has no NaN or infinity, so a value that is not finite is written as ``null``
(:func:`finite_or_none`); :func:`jsonable` turns numpy values, arrays and tuples into plain Python
throughout a nested structure, and :func:`dump` writes one line of strict JSON::

    from studies.jsonio import dump, finite_or_none, jsonable
    dump({"sigma_min": np.float64(0.0), "condition": np.inf})    # '{"sigma_min": 0.0, "condition": null}'
"""
from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["finite_or_none", "jsonable", "dump"]


def finite_or_none(x) -> float | None:
    """A number as a float, or None when it is None, NaN or infinite (JSON's ``null``)."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def jsonable(obj):
    """numpy values → plain Python; NaN and infinities → None (strict JSON)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (np.floating, float)):
        return finite_or_none(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def dump(obj) -> str:
    """One line of strict JSON."""
    return json.dumps(jsonable(obj), allow_nan=False)
