"""Singular error windows: a neighbourhood in joint space around each factor of the singular set.

A window belongs to one factor g of det J (see :mod:`kin.singular`):

* a factor of one joint j gives a union of intervals of q_j around its roots, r ± w;
* a component of a numerically found singular set (no formula) gives a point-set window: every
  configuration within w of its sampled points (:mod:`planning.windows.sampled`);
* any other factor gives the predicate |g(q)| ≤ ε, with ε = w · max‖∇g‖ over sampled points of
  its zero set, so that every configuration within (first-order) joint distance w of the zero set
  is inside — the window is at least w wide everywhere.

The width w (rad for revolute joints, m for prismatic ones, SI) comes from an explicit margin,
from a dexterity threshold (the smallest margin outside which σ_min ≥ s, or manipulability ≥ m,
found by sampling the factor's neighbourhood), or from a learned-IK error (``design.learned.ik``).
Windows save to and load from JSON; membership of a batch is vectorised.

The values are in :mod:`planning.windows.model`, their construction in :mod:`planning.windows.build`.
"""
from planning.windows.build import build_windows, dexterity_margins, window_for_factor
from planning.windows.model import METHODS, Window, WindowSet
from planning.windows.sampled import PointSetWindow

__all__ = ["Window", "WindowSet", "PointSetWindow", "METHODS", "build_windows", "dexterity_margins",
           "window_for_factor"]
