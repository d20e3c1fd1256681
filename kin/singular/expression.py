"""A safe reader for singular-factor expressions (the ``expr`` of a saved window, a factor typed by a user).

The text is never given to ``eval`` or :func:`sympy.sympify` (which evaluates Python): it is parsed
with the grammar below into the small immutable tree of :mod:`kin.singular.tree`
(:func:`parse_tree`), which :mod:`kin.singular.evaluate` turns into numpy and plain-float
functions; :func:`parse_expression` builds the sympy expression from that tree for the symbolic
side.  Anything outside the grammar is refused with a one-line :class:`ExpressionError` naming the
position (1-based character) and what was expected.  This module does not import sympy until a
sympy expression is asked for.

Grammar (whitespace between tokens is ignored)::

    expr   := term   (("+" | "-") term)*
    term   := unary  (("*" | "/") unary)*
    unary  := ("-" | "+") unary | power
    power  := atom   (("^" | "**") unary)?         right-associative: 2^3^2 = 2^9
    atom   := NUMBER | "q" INDEX | ("sin" | "cos") "(" expr ")" | "(" expr ")"
    NUMBER := digits ["." digits] [("e" | "E") ["+" | "-"] digits]  (or "." digits ...)
    INDEX  := 1 … n  (the joint variables q1…qn of an n-joint chain)

``−``, ``×`` and ``÷`` are accepted for ``-``, ``*`` and ``/``.  Exponents must be constant
integers within ±:data:`MAX_EXPONENT` (integer arithmetic on integers is exact: ``q1^(4/2)`` is
``q1^2``); constant sub-expressions are folded in floating point and must stay finite; a division
by an exact zero (a constant 0, or joint variables that cancel: ``q1/(q2 - q2)``) is refused;
nesting is limited to :data:`MAX_DEPTH` and the text to :data:`MAX_LENGTH` characters.  The joint
symbols are those of :mod:`kin.singular.sympy_model` (``sympy.Symbol("q<i>", real=True)``); a tree
becomes a sympy expression with :func:`to_sympy`, and back with :mod:`kin.singular.tree_sympy`.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING

from kin.errors import RmtError
from kin.singular.tree import Add, Cos, Mul, Node, Num, Pow, Sin, Var, add, mul, neg
from kin.validation import is_count

if TYPE_CHECKING:
    import sympy as sp

__all__ = ["ExpressionError", "parse_tree", "parse_expression", "joint_symbols", "to_sympy", "MAX_EXPONENT",
           "MAX_DEPTH", "MAX_LENGTH"]

MAX_EXPONENT = 64
MAX_DEPTH = 100
MAX_LENGTH = 100_000
#: exact constants longer than this (bits of numerator or denominator) continue as floats
_EXACT_BITS = 1100

_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<op>\*\*|[-+*/^()−×÷])
""", re.VERBOSE)
_OP_ALIASES = {"−": "-", "×": "*", "÷": "/"}
_FUNCTIONS = {"sin": Sin, "cos": Cos}


class ExpressionError(RmtError, ValueError):
    """An expression is outside the grammar of :mod:`kin.singular.expression`."""


@dataclass(frozen=True)
class _Tok:
    kind: str       # "number" | "name" | "op" | "end"
    text: str
    pos: int        # 1-based character position


@dataclass(frozen=True)
class _C:
    """A constant while parsing: its float value and, for integer arithmetic on integers (sympy's
    Integer/Rational), the exact value (None once a float entered)."""

    value: float
    exact: Fraction | None = None


def _const(value: float, exact: Fraction | None) -> _C:
    if exact is not None and max(exact.numerator.bit_length(), exact.denominator.bit_length()) > _EXACT_BITS:
        exact = None
    if exact is not None:
        try:
            value = float(exact)
        except OverflowError:
            value = math.inf
    return _C(value, exact)


def joint_symbols(n: int) -> tuple[sp.Symbol, ...]:
    """The joint variables q1…qn as real sympy symbols (imports sympy)."""
    import sympy as sp
    return tuple(sp.Symbol(f"q{i + 1}", real=True) for i in range(n))


def _tokens(text: str, where: str) -> list[_Tok]:
    out, i = [], 0
    while i < len(text):
        m = _TOKEN.match(text, i)
        if m is None:
            raise ExpressionError(f"{where}: unexpected character {text[i]!r} at position {i + 1}; allowed: "
                                  "numbers, q1…qn, + - * / ^ **, sin, cos, parentheses")
        kind = m.lastgroup
        if kind != "space":
            tok = m.group()
            out.append(_Tok(kind, _OP_ALIASES.get(tok, tok), i + 1))
        i = m.end()
    out.append(_Tok("end", "", len(text) + 1))
    return out


def _node(e: Node | _C) -> Node:
    return Num(e.value) if isinstance(e, _C) else e


def _cancels(e: Node) -> bool:
    """Whether e is a linear form in the joint variables whose coefficients all cancel (``q2 - q2``),
    i.e. zero although not folded to a constant."""
    coefs: dict[int, float] = {}

    def walk(u: Node, scale: float) -> bool:
        if isinstance(u, Num):
            coefs[-1] = coefs.get(-1, 0.0) + scale * u.value
            return True
        if isinstance(u, Var):
            coefs[u.index] = coefs.get(u.index, 0.0) + scale
            return True
        if isinstance(u, Mul) and len(u.factors) == 2 and isinstance(u.factors[0], Num):
            return walk(u.factors[1], scale * u.factors[0].value)
        if isinstance(u, Add):
            return all(walk(t, scale) for t in u.terms)
        return False
    return walk(e, 1.0) and all(c == 0.0 for c in coefs.values())


class _Parser:
    def __init__(self, text: str, n: int, where: str):
        self.where = where
        self.toks = _tokens(text, where)
        self.k = 0
        self.n = n
        self.depth = 0

    # ---- helpers -------------------------------------------------------------------------------
    @property
    def tok(self) -> _Tok:
        return self.toks[self.k]

    def fail(self, msg: str, tok: _Tok | None = None) -> ExpressionError:
        t = tok or self.tok
        got = "the end of the expression" if t.kind == "end" else repr(t.text)
        return ExpressionError(f"{self.where}: {msg} at position {t.pos} (found {got})")

    def eat(self, text: str) -> bool:
        if self.tok.kind == "op" and self.tok.text == text:
            self.k += 1
            return True
        return False

    def nest(self):
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.fail(f"expression nested deeper than {MAX_DEPTH} levels")

    def finite(self, c: _C, tok: _Tok) -> _C:
        """A constant result must be a finite double (no overflow)."""
        if not math.isfinite(c.value):
            raise self.fail("a constant is not a finite number (overflow or division by zero)", tok)
        return c

    # ---- grammar -------------------------------------------------------------------------------
    def parse(self) -> Node:
        e = self.expr()
        if self.tok.kind != "end":
            raise self.fail("expected an operator (+ - * / ^) or the end")
        return _node(e)

    def expr(self) -> Node | _C:
        first = self.term()
        terms: list[Node] = []
        const: _C | None = None
        for sign, e, op in [("+", first, None), *self._more(("+", "-"), self.term)]:
            if isinstance(e, _C):
                if sign == "-":
                    e = _C(-e.value, None if e.exact is None else -e.exact)
                if const is None:
                    const = e
                else:
                    exact = const.exact + e.exact if const.exact is not None and e.exact is not None else None
                    const = self.finite(_const(const.value + e.value, exact), op)
            else:
                terms.append(e if sign == "+" else neg(e))
        if not terms:
            return const
        return add([*terms, Num(const.value)] if const is not None else terms)

    def _more(self, ops: tuple[str, ...], parse):
        """(operator, operand, token) of each further operand of a chain ``a op b op c …``."""
        while self.tok.kind == "op" and self.tok.text in ops:
            op = self.tok
            self.k += 1
            yield op.text, parse(), op

    def term(self) -> Node | _C:
        first = self.unary()
        factors: list[Node] = []
        coef: _C | None = None
        for opt, e, op in [("*", first, None), *self._more(("*", "/"), self.unary)]:
            if not isinstance(e, _C):
                if opt == "/" and _cancels(e):
                    raise self.fail("division by zero", op)
                factors.append(e if opt == "*" else Pow(e.base, -e.exp) if isinstance(e, Pow) else Pow(e, -1))
            elif opt == "/":
                if e.value == 0.0:
                    raise self.fail("division by zero", op)
                a = coef or _C(1.0, Fraction(1))
                exact = a.exact / e.exact if a.exact is not None and e.exact is not None else None
                coef = self.finite(_const(a.value / e.value, exact), op)
            elif coef is None:
                coef = e
            else:
                exact = coef.exact * e.exact if coef.exact is not None and e.exact is not None else None
                coef = self.finite(_const(coef.value * e.value, exact), op)
        if not factors:
            return coef
        if coef is not None and coef.value == 0.0:
            return _C(0.0, Fraction(0))                 # 0 times anything is 0 (sympy's rule)
        return mul([Num(coef.value), *factors] if coef is not None else factors)

    def unary(self) -> Node | _C:
        if self.tok.kind == "op" and self.tok.text in "+-":
            sign = self.tok.text
            self.k += 1
            self.nest()
            e = self.unary()
            self.depth -= 1
            if sign == "+":
                return e
            return _C(-e.value, None if e.exact is None else -e.exact) if isinstance(e, _C) else neg(e)
        return self.power()

    def power(self) -> Node | _C:
        base = self.atom()
        if self.tok.kind == "op" and self.tok.text in ("^", "**"):
            op = self.tok
            self.k += 1
            self.nest()
            exp_tok = self.tok
            ex = self.unary()
            self.depth -= 1
            if not (isinstance(ex, _C) and ex.exact is not None and ex.exact.denominator == 1
                    and abs(ex.exact) <= MAX_EXPONENT):
                raise self.fail(f"an exponent must be a constant integer within ±{MAX_EXPONENT}", exp_tok)
            k = int(ex.exact)
            if isinstance(base, _C):
                if base.value == 0.0 and k < 0:
                    raise self.fail("division by zero (0 to a negative power)", op)
                try:
                    value = float(base.value) ** k
                except OverflowError:
                    value = math.inf
                if not math.isfinite(value):
                    raise self.fail("a constant is not a finite number (overflow)", op)
                integer = base.exact is not None and base.exact.denominator == 1
                return _C(value, Fraction(int(value)) if integer and k >= 0 and abs(value) < 2**53 else None)
            if k < 0 and _cancels(base):
                raise self.fail("division by zero", op)
            if k == 0:
                return _C(1.0, Fraction(1))
            return base if k == 1 else Pow(base, k)
        return base

    def atom(self) -> Node | _C:
        t = self.tok
        if t.kind == "number":
            self.k += 1
            v = float(t.text)
            if not math.isfinite(v):
                raise self.fail("number out of range (not a finite double)", t)
            if re.fullmatch(r"\d+", t.text) and v < 2**53:
                return _C(v, Fraction(int(t.text)))
            return _C(v)
        if t.kind == "name":
            self.k += 1
            m = re.fullmatch(r"q([1-9]\d*)", t.text)
            if m:
                i = int(m.group(1))
                if i > self.n:
                    raise self.fail(f"joint variable out of range; this chain has q1…q{self.n}", t)
                return Var(i - 1)
            if t.text in _FUNCTIONS:
                if not self.eat("("):
                    raise self.fail(f"expected '(' after {t.text}")
                self.nest()
                arg = self.expr()
                self.depth -= 1
                if not self.eat(")"):
                    raise self.fail(f"expected ')' closing {t.text}(")
                if isinstance(arg, _C):                 # sin(0) = 0 and cos(0) = 1 exactly, as sympy's
                    zero = arg.exact == 0
                    if t.text == "sin":
                        return _C(0.0, Fraction(0)) if zero else _C(math.sin(arg.value))
                    return _C(1.0, Fraction(1)) if zero else _C(math.cos(arg.value))
                return _FUNCTIONS[t.text](arg)
            raise self.fail(f"unknown name; allowed: q1…q{self.n}, sin, cos", t)
        if self.eat("("):
            self.nest()
            e = self.expr()
            self.depth -= 1
            if not self.eat(")"):
                raise self.fail("expected ')'")
            return e
        raise self.fail("expected a number, q1…qn, sin(…), cos(…) or '('")


def parse_tree(text: str, n: int, where: str = "expression") -> Node:
    """Parse ``text`` (see the module grammar) over the joint variables q1…qn → its tree
    (:mod:`kin.singular.tree`; the variables 0-based).

    ``where`` names the source (a file and field) in the error message.  Raises
    :class:`ExpressionError` (one line, with the 1-based position) for anything else.
    """
    if not isinstance(text, str):
        raise ExpressionError(f"{where}: must be a string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"{where}: {len(text)} characters; at most {MAX_LENGTH}")
    if not is_count(n) or n < 1:
        raise ExpressionError(f"{where}: the number of joints must be a positive integer, got {n!r}")
    return _Parser(text, n, where).parse()


def parse_expression(text: str, n: int, where: str = "expression") -> sp.Expr:
    """Parse ``text`` (see the module grammar) over the joint variables q1…qn → a sympy expression
    (built from :func:`parse_tree`'s tree; imports sympy).

    ``where`` names the source (a file and field) in the error message.  Raises
    :class:`ExpressionError` (one line, with the 1-based position) for anything else, and for a
    divisor that sympy simplifies to 0 (``q1/(q2 - q2)``).
    """
    import sympy as sp
    expr = to_sympy(parse_tree(text, n, where), n)
    if expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise ExpressionError(f"{where}: division by zero (a divisor simplifies to 0)")
    return expr


def to_sympy(tree: Node, n: int) -> sp.Expr:
    """The sympy expression of a tree over q1…qn (:func:`joint_symbols`; imports sympy)."""
    import sympy as sp
    q = joint_symbols(n)

    def build(e: Node):
        if isinstance(e, Num):
            v = e.value
            return sp.Integer(int(v)) if v.is_integer() and abs(v) < 2**53 else sp.Float(v)
        if isinstance(e, Var):
            return q[e.index]
        if isinstance(e, Add):
            return sp.Add(*[build(t) for t in e.terms])
        if isinstance(e, Mul):
            return sp.Mul(*[build(f) for f in e.factors])
        if isinstance(e, Pow):
            return sp.Pow(build(e.base), sp.Integer(e.exp))
        if isinstance(e, Sin):
            return sp.sin(build(e.arg))
        if isinstance(e, Cos):
            return sp.cos(build(e.arg))
        raise TypeError(f"not an expression tree node: {e!r}")
    return build(tree)
