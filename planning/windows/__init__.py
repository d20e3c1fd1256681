"""Singular error windows: a neighbourhood in joint space around each factor of the singular set.

A window belongs to one factor g of det J (see :mod:`kin.singular`) and a half-width w (rad for
revolute joints, m for prismatic ones, SI).  It holds every configuration within joint distance w of
the factor's zero set, and it is a function of the robot, the factor and w alone — no seed, sample
count or cache changes it, so every command builds the same window:

* a factor of one joint j gives a union of intervals of q_j around its roots, r ± w (exact);
* any other factor gives the predicate |g(q)| ≤ ε with ε = w · G, where G is a bound of ‖∇g‖ over
  the whole joint box (the limits) proven by interval arithmetic
  (:func:`planning.certify.gradient.gradient_bound`, within 0.1 % of the true maximum).  By the mean
  value theorem |g(q)| ≤ G·‖q − z‖ for a zero z, so the w-neighbourhood of the zero set is inside —
  a proof, not a first-order estimate.  Where ‖∇g‖ is smaller than G the window is wider than w
  (up to w·G/‖∇g‖);
* a component of a numerically found singular set (no formula) gives a point-set window: every
  configuration within w of its sampled points (:mod:`planning.windows.sampled`).  It is labelled
  ``"sampled"``: it holds the set only as far as its samples show (``detail["resolution"]``).

The width comes from an explicit margin,
from a dexterity threshold (the smallest margin outside which σ_min ≥ s, or manipulability ≥ m,
found by sampling the factor's neighbourhood; the floor is then sampled, not proven, and
``detail["floor"]`` gives its miss rate on fresh configurations), or from a learned-IK error
(``design.learned.ik``).
Windows save to and load from JSON; membership of a batch is vectorised.

The values are in :mod:`planning.windows.model`, their construction in :mod:`planning.windows.build`,
built windows kept on disk in :mod:`planning.windows.cache`.
"""
from planning.windows.base import WindowBase
from planning.windows.model import METHODS, Window, WindowSet
from planning.windows.sampled import PointSetWindow

__all__ = ["WindowBase", "Window", "WindowSet", "PointSetWindow", "METHODS", "build_windows", "dexterity_margins",
           "window_for_factor"]

#: built on first use: building needs the symbolic side of kin.singular (sympy), using built
#: windows (loaded from a file or the cache) does not
_BUILD = {"build_windows", "dexterity_margins", "window_for_factor"}


def __getattr__(name: str):
    if name in _BUILD:
        from planning.windows import build
        return getattr(build, name)
    raise AttributeError(f"module 'planning.windows' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | _BUILD)
