"""Named configurations of a robot ("home", "up"): the robot file's ``[states]`` table.

A state is a full configuration, one value per joint, written in the robot file's units (its angle
unit for revolute joints, its length unit for prismatic ones) and kept in SI by
:attr:`kin.chain.Chain.states`.  A state must lie inside the joint limits.  Its name starts with a
letter and holds letters, digits, ``_``, ``.`` and ``-`` (at most 64 characters), and is never a
number (``inf``, ``nan`` are refused): wherever a configuration is taken on the command line a single
non-numeric word is read as a state's name (``rmt fk ur5e home``, ``--start home``).

MoveIt calls them *group states* (an SRDF's ``<group_state>``, read by :mod:`kin.urdf.srdf`).
"""
from __future__ import annotations

import re
from typing import Any, Mapping

import numpy as np

from kin.display import joint_label
from kin.errors import ChainError, RmtError

__all__ = ["STATE_NAME_RE", "MAX_STATES", "UnknownStateError", "name_problem", "checked_states", "read_states",
           "state_lines", "state", "is_number"]

#: the names a state may have
STATE_NAME_RE = re.compile(r"[A-Za-z][A-Za-z0-9_.\-]{0,63}")
#: at most this many states in one robot
MAX_STATES = 100


class UnknownStateError(RmtError, KeyError):
    """A configuration was asked for by a name the robot has no state of; the message lists its states."""

    def __str__(self) -> str:      # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


def name_problem(name: Any) -> str | None:
    """Why ``name`` cannot name a state (None when it can)."""
    if not isinstance(name, str) or not STATE_NAME_RE.fullmatch(name):
        return (f"{name!r} is not a state name: a letter, then letters, digits, '_', '.' or '-' "
                "(at most 64 characters)")
    try:
        float(name)
    except ValueError:
        return None
    return f"{name!r} reads as a number; a state name must not"


def values_problem(chain, q_si) -> str | None:
    """Why the SI configuration ``q_si`` cannot be a state of ``chain`` (count, finiteness, limits;
    values said in the chain's file units), or None."""
    q = np.asarray(q_si, dtype=float)
    if q.shape != (chain.n,):
        return f"has {q.size} values; {chain.name} has {chain.n} joints"
    if not np.all(np.isfinite(q)):
        j = int(np.flatnonzero(~np.isfinite(q))[0])
        return f"{joint_label(chain, j)} = {q[j]} is not a finite number"
    out = np.flatnonzero((q < chain.lower) | (q > chain.upper))
    if out.size:
        j = int(out[0])
        f = chain.from_si(q)[j]
        lo, hi = chain.from_si(chain.lower)[j], chain.from_si(chain.upper)[j]
        unit = chain.angle_unit if chain.joints[j].is_revolute else chain.length_unit
        return f"{joint_label(chain, j)} = {f:.6g} {unit} lies outside its limits [{lo:.6g}, {hi:.6g}] {unit}"
    return None


def checked_states(chain, states: Mapping[str, Any]) -> dict[str, tuple[float, ...]]:
    """``states`` (name → SI configuration) checked against ``chain``; :class:`ChainError` otherwise."""
    if not isinstance(states, Mapping):
        raise ChainError(f"states must be a mapping of names to configurations, got {type(states).__name__}")
    if len(states) > MAX_STATES:
        raise ChainError(f"{len(states)} states; at most {MAX_STATES} are allowed")
    out = {}
    for name, q in states.items():
        why = name_problem(name)
        if why is None:
            try:
                arr = np.asarray(q, dtype=float)
            except (TypeError, ValueError):
                why = f"state {name!r} is not a list of numbers"
            else:
                msg = values_problem(chain, arr)
                why = None if msg is None else f"state {name!r} {msg}"
        if why is not None:
            raise ChainError(why)
        out[name] = tuple(float(x) for x in arr)
    return out


def read_states(r, raw: Any, chain) -> dict[str, tuple[float, ...]]:
    """The robot file's ``[states]`` table → name → SI configuration, each checked (``r``: the robot
    file's field reader, :class:`kin.validation.Fields`; errors name ``states.NAME``)."""
    if not isinstance(raw, dict):
        raise r.fail("states", "must be a table of named configurations, e.g. [states] then home = [0, -90, ...]")
    if len(raw) > MAX_STATES:
        raise r.fail("states", f"lists {len(raw)} states; at most {MAX_STATES} are allowed")
    out = {}
    for name, v in raw.items():
        fld = f"states.{name}"
        why = name_problem(name)
        if why is not None:
            raise r.fail(fld, why)
        q = chain.to_si(r.vector(v, fld, chain.n))
        why = values_problem(chain, q)
        if why is not None:
            raise r.fail(fld, why)
        out[name] = tuple(float(x) for x in q)
    return out


def state_lines(chain, value_text) -> list[str]:
    """The ``[states]`` table of a robot file (none when the chain has no state); ``value_text(x_si,
    scale)`` writes one value in file units."""
    if not chain.states:
        return []
    scale = chain.variable_scale
    out = ["", "[states]"]
    for name, q in chain.states.items():
        out.append(f"{name} = [" + ", ".join(value_text(x, s) for x, s in zip(q, scale)) + "]")
    return out


def state(chain, name: str) -> np.ndarray:
    """The SI configuration (n,) of ``chain``'s state ``name``; :class:`UnknownStateError` (listing
    the states) when it has none of that name."""
    if name in chain.states:
        return np.array(chain.states[name], dtype=float)
    have = ", ".join(chain.states) if chain.states else "none (a robot file lists them in a [states] table)"
    raise UnknownStateError(f"{chain.name} has no state named {name!r}; its states: {have}")


def is_number(text: str) -> bool:
    """True when ``text`` reads as a number (finite or not)."""
    try:
        float(text)
    except ValueError:
        return False
    return True
