"""The expression tree of a singular factor: small immutable nodes, built by the safe reader of
:mod:`kin.singular.expression` and evaluated by :mod:`kin.singular.evaluate` (numpy batches, plain
floats) and by :mod:`planning.certify.intervals` (interval boxes) — no sympy anywhere.

Nodes: :class:`Num` (a float), :class:`Var` (the joint variable q_{index+1}), :class:`Add`,
:class:`Mul` (a numeric coefficient, when there is one, is the first factor), :class:`Pow` (an
integer exponent, negative for a division), :class:`Sin` and :class:`Cos`.  The builders
:func:`add`, :func:`mul`, :func:`power` and :func:`neg` flatten nested sums and products and fold
their numbers in floating point, so a tree holds at most one number per sum and per product.
``str(node)`` writes a tree back in the grammar of :mod:`kin.singular.expression`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

__all__ = ["Node", "Num", "Var", "Add", "Mul", "Pow", "Sin", "Cos", "add", "mul", "power", "neg",
           "derivative", "variables", "to_text"]


class Node:
    """Base of the tree nodes (immutable, hashable, compared by value)."""

    __slots__ = ()

    def __str__(self) -> str:
        return to_text(self)


@dataclass(frozen=True, slots=True)
class Num(Node):
    """A number."""

    value: float


@dataclass(frozen=True, slots=True)
class Var(Node):
    """The joint variable q_{index+1} (``index`` 0-based)."""

    index: int


@dataclass(frozen=True, slots=True)
class Add(Node):
    """The sum of ``terms`` (two or more)."""

    terms: tuple[Node, ...]


@dataclass(frozen=True, slots=True)
class Mul(Node):
    """The product of ``factors`` (two or more; a :class:`Num` only as the first)."""

    factors: tuple[Node, ...]


@dataclass(frozen=True, slots=True)
class Pow(Node):
    """``base`` to the integer power ``exp`` (≠ 0, 1)."""

    base: Node
    exp: int


@dataclass(frozen=True, slots=True)
class Sin(Node):
    """sin(``arg``), radians."""

    arg: Node


@dataclass(frozen=True, slots=True)
class Cos(Node):
    """cos(``arg``), radians."""

    arg: Node


# ---- builders ------------------------------------------------------------------------------------
def add(terms: Iterable[Node]) -> Node:
    """The sum of ``terms``: nested sums flattened, the numbers folded into one last term (dropped
    when 0) → a :class:`Num` when nothing else is left, the only term when one is."""
    out: list[Node] = []
    const: float | None = None
    for t in terms:
        for u in (t.terms if isinstance(t, Add) else (t,)):
            if isinstance(u, Num):
                const = u.value if const is None else const + u.value
            else:
                out.append(u)
    if const is not None and (const != 0.0 or not out):
        out.append(Num(const))
    if not out:
        return Num(0.0)
    return out[0] if len(out) == 1 else Add(tuple(out))


def mul(factors: Iterable[Node]) -> Node:
    """The product of ``factors``: nested products flattened, the numbers folded into a first
    coefficient (dropped when 1) → ``Num(0.0)`` when the coefficient is 0, the only factor when one is."""
    out: list[Node] = []
    coef: float | None = None
    for f in factors:
        for u in (f.factors if isinstance(f, Mul) else (f,)):
            if isinstance(u, Num):
                coef = u.value if coef is None else coef * u.value
            else:
                out.append(u)
    if coef is not None and coef == 0.0:
        return Num(0.0)
    if coef is not None and (coef != 1.0 or not out):
        out.insert(0, Num(coef))
    if not out:
        return Num(1.0)
    return out[0] if len(out) == 1 else Mul(tuple(out))


def power(base: Node, k: int) -> Node:
    """``base`` to the integer power ``k``: 1 for k = 0, the base for k = 1, a number for a number
    base (the caller checks it is finite), (b^j)^−1 written b^−j."""
    k = int(k)
    if k == 0:
        return Num(1.0)
    if k == 1:
        return base
    if isinstance(base, Num):
        return Num(base.value ** k)
    if k == -1 and isinstance(base, Pow):
        return Pow(base.base, -base.exp)
    return Pow(base, k)


def neg(e: Node) -> Node:
    """−e (a number negated, a product's coefficient negated)."""
    return Num(-e.value) if isinstance(e, Num) else mul((Num(-1.0), e))


# ---- analysis -------------------------------------------------------------------------------------
def derivative(e: Node, j: int) -> Node:
    """∂e/∂q_{j+1} (``j`` 0-based), as a tree (zero terms dropped)."""
    if isinstance(e, Num):
        return Num(0.0)
    if isinstance(e, Var):
        return Num(1.0 if e.index == j else 0.0)
    if isinstance(e, Add):
        return add(derivative(t, j) for t in e.terms)
    if isinstance(e, Mul):
        terms = []
        for i, f in enumerate(e.factors):
            d = derivative(f, j)
            if not (isinstance(d, Num) and d.value == 0.0):
                terms.append(mul((*e.factors[:i], d, *e.factors[i + 1:])))
        return add(terms)
    if isinstance(e, Pow):
        d = derivative(e.base, j)
        if isinstance(d, Num) and d.value == 0.0:
            return d
        return mul((Num(float(e.exp)), power(e.base, e.exp - 1), d))
    if isinstance(e, Sin):
        d = derivative(e.arg, j)
        return d if isinstance(d, Num) and d.value == 0.0 else mul((Cos(e.arg), d))
    if isinstance(e, Cos):
        d = derivative(e.arg, j)
        return d if isinstance(d, Num) and d.value == 0.0 else mul((Num(-1.0), Sin(e.arg), d))
    raise TypeError(f"not an expression tree node: {e!r}")


def variables(e: Node) -> frozenset[int]:
    """The 0-based joint indices the tree holds."""
    if isinstance(e, Var):
        return frozenset((e.index,))
    if isinstance(e, Num):
        return frozenset()
    if isinstance(e, (Add, Mul)):
        parts = e.terms if isinstance(e, Add) else e.factors
        return frozenset().union(*(variables(p) for p in parts))
    if isinstance(e, Pow):
        return variables(e.base)
    return variables(e.arg)


def _num_text(v: float) -> str:
    return repr(float(v))


def to_text(e: Node) -> str:
    """The tree in the grammar of :mod:`kin.singular.expression` (numbers written exactly, as
    ``repr`` of the float), so that reading the text gives the same tree back."""
    if isinstance(e, Num):
        return _num_text(e.value) if e.value >= 0 or e.value != e.value else f"({_num_text(e.value)})"
    if isinstance(e, Var):
        return f"q{e.index + 1}"
    if isinstance(e, Add):
        out = to_text(e.terms[0])
        for t in e.terms[1:]:
            if isinstance(t, Num) and t.value < 0:
                out += f" - {_num_text(-t.value)}"
            elif isinstance(t, Mul) and isinstance(t.factors[0], Num) and t.factors[0].value < 0:
                m = neg(t)               # −(a + b) must keep its brackets: "x - (a + b)", not "x - a + b"
                out += f" - ({to_text(m)})" if isinstance(m, Add) else f" - {to_text(m)}"
            else:
                out += f" + {to_text(t)}"
        return out
    if isinstance(e, Mul):
        parts = list(e.factors)
        head = ""
        if isinstance(parts[0], Num) and parts[0].value == -1.0:
            head, parts = "-", parts[1:]
        return head + "*".join(f"({to_text(f)})" if isinstance(f, Add) else to_text(f) for f in parts)
    if isinstance(e, Pow):
        b = to_text(e.base)
        if not isinstance(e.base, (Var, Sin, Cos)) and not (isinstance(e.base, Num) and e.base.value >= 0):
            b = f"({b})"
        return f"{b}^{e.exp}" if e.exp > 0 else f"{b}^({e.exp})"
    if isinstance(e, Sin):
        return f"sin({to_text(e.arg)})"
    if isinstance(e, Cos):
        return f"cos({to_text(e.arg)})"
    raise TypeError(f"not an expression tree node: {e!r}")
