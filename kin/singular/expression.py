"""A safe reader for singular-factor expressions (the ``expr`` of a saved window, a factor typed by a user).

The text is never given to ``eval`` or :func:`sympy.sympify` (which evaluates Python): it is parsed
with the grammar below and the sympy expression is built from the parse tree.  Anything outside
the grammar is refused with a one-line :class:`ExpressionError` naming the position (1-based
character) and what was expected.

Grammar (whitespace between tokens is ignored)::

    expr   := term   (("+" | "-") term)*
    term   := unary  (("*" | "/") unary)*
    unary  := ("-" | "+") unary | power
    power  := atom   (("^" | "**") unary)?         right-associative: 2^3^2 = 2^9
    atom   := NUMBER | "q" INDEX | ("sin" | "cos") "(" expr ")" | "(" expr ")"
    NUMBER := digits ["." digits] [("e" | "E") ["+" | "-"] digits]  (or "." digits ...)
    INDEX  := 1 … n  (the joint variables q1…qn of an n-joint chain)

``−``, ``×`` and ``÷`` are accepted for ``-``, ``*`` and ``/``.  Exponents must be constant
integers within ±:data:`MAX_EXPONENT`; constant sub-expressions are folded in floating point and
must stay finite; a division by an exact zero is refused; nesting is limited to
:data:`MAX_DEPTH` and the text to :data:`MAX_LENGTH` characters.  The joint symbols are those of
:mod:`kin.singular.sympy_model` (``sympy.Symbol("q<i>", real=True)``).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import sympy as sp

from kin.errors import RmtError

__all__ = ["ExpressionError", "parse_expression", "joint_symbols", "MAX_EXPONENT", "MAX_DEPTH", "MAX_LENGTH"]

MAX_EXPONENT = 64
MAX_DEPTH = 100
MAX_LENGTH = 100_000

_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<op>\*\*|[-+*/^()−×÷])
""", re.VERBOSE)
_OP_ALIASES = {"−": "-", "×": "*", "÷": "/"}
_FUNCTIONS = {"sin": sp.sin, "cos": sp.cos}


class ExpressionError(RmtError, ValueError):
    """An expression is outside the grammar of :mod:`kin.singular.expression`."""


@dataclass(frozen=True)
class _Tok:
    kind: str       # "number" | "name" | "op" | "end"
    text: str
    pos: int        # 1-based character position


def joint_symbols(n: int) -> tuple[sp.Symbol, ...]:
    """The joint variables q1…qn as real sympy symbols."""
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


class _Parser:
    def __init__(self, text: str, n: int, where: str):
        self.where = where
        self.toks = _tokens(text, where)
        self.k = 0
        self.q = joint_symbols(n)
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

    def finite(self, e: sp.Expr, tok: _Tok) -> sp.Expr:
        """A constant result must be a finite double (no overflow, no ``zoo``/``nan``)."""
        if e.is_Number or e.has(sp.zoo, sp.oo, sp.nan):
            try:
                ok = bool(e.is_finite) and math.isfinite(float(e))
            except (OverflowError, TypeError, ValueError):
                ok = False
            if not ok:
                raise self.fail("a constant is not a finite number (overflow or division by zero)", tok)
        return e

    # ---- grammar -------------------------------------------------------------------------------
    def parse(self) -> sp.Expr:
        e = self.expr()
        if self.tok.kind != "end":
            raise self.fail("expected an operator (+ - * / ^) or the end")
        return e

    def expr(self) -> sp.Expr:
        terms = [self.term()]
        op = None
        while self.tok.kind == "op" and self.tok.text in "+-":
            op = self.tok
            self.k += 1
            r = self.term()
            terms.append(r if op.text == "+" else -r)
        return terms[0] if op is None else self.finite(sp.Add(*terms), op)

    def term(self) -> sp.Expr:
        factors = [self.unary()]
        op = None
        while self.tok.kind == "op" and self.tok.text in ("*", "/"):
            op = self.tok
            self.k += 1
            r = self.unary()
            if op.text == "/":
                if r.is_zero:
                    raise self.fail("division by zero", op)
                r = sp.Pow(r, -1)
            factors.append(r)
        return factors[0] if op is None else self.finite(sp.Mul(*factors), op)

    def unary(self) -> sp.Expr:
        if self.tok.kind == "op" and self.tok.text in "+-":
            sign = self.tok.text
            self.k += 1
            self.nest()
            e = self.unary()
            self.depth -= 1
            return -e if sign == "-" else e
        return self.power()

    def power(self) -> sp.Expr:
        base = self.atom()
        if self.tok.kind == "op" and self.tok.text in ("^", "**"):
            op = self.tok
            self.k += 1
            self.nest()
            exp_tok = self.tok
            ex = self.unary()
            self.depth -= 1
            if not (ex.is_Number and ex.is_integer and abs(int(ex)) <= MAX_EXPONENT):
                raise self.fail(f"an exponent must be a constant integer within ±{MAX_EXPONENT}", exp_tok)
            k = int(ex)
            if base.is_Number:
                if base.is_zero and k < 0:
                    raise self.fail("division by zero (0 to a negative power)", op)
                try:
                    value = float(base) ** k
                except OverflowError:
                    value = math.inf
                if not math.isfinite(value):
                    raise self.fail("a constant is not a finite number (overflow)", op)
                return sp.Integer(int(value)) if base.is_Integer and k >= 0 and abs(value) < 2**53 else sp.Float(value)
            if base.is_zero is True and k < 0:
                raise self.fail("division by zero", op)
            return sp.Pow(base, sp.Integer(k))
        return base

    def atom(self) -> sp.Expr:
        t = self.tok
        if t.kind == "number":
            self.k += 1
            v = float(t.text)
            if not math.isfinite(v):
                raise self.fail("number out of range (not a finite double)", t)
            if re.fullmatch(r"\d+", t.text) and v < 2**53:
                return sp.Integer(int(t.text))
            return sp.Float(v)
        if t.kind == "name":
            self.k += 1
            m = re.fullmatch(r"q([1-9]\d*)", t.text)
            if m:
                i = int(m.group(1))
                if i > self.n:
                    raise self.fail(f"joint variable out of range; this chain has q1…q{self.n}", t)
                return self.q[i - 1]
            if t.text in _FUNCTIONS:
                if not self.eat("("):
                    raise self.fail(f"expected '(' after {t.text}")
                self.nest()
                arg = self.expr()
                self.depth -= 1
                if not self.eat(")"):
                    raise self.fail(f"expected ')' closing {t.text}(")
                return self.finite(_FUNCTIONS[t.text](arg), t)
            raise self.fail(f"unknown name; allowed: q1…q{self.n}, sin, cos", t)
        if self.eat("("):
            self.nest()
            e = self.expr()
            self.depth -= 1
            if not self.eat(")"):
                raise self.fail("expected ')'")
            return e
        raise self.fail("expected a number, q1…qn, sin(…), cos(…) or '('")


def parse_expression(text: str, n: int, where: str = "expression") -> sp.Expr:
    """Parse ``text`` (see the module grammar) over the joint variables q1…qn → a sympy expression.

    ``where`` names the source (a file and field) in the error message.  Raises
    :class:`ExpressionError` (one line, with the 1-based position) for anything else.
    """
    if not isinstance(text, str):
        raise ExpressionError(f"{where}: must be a string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"{where}: {len(text)} characters; at most {MAX_LENGTH}")
    if not isinstance(n, int) or n < 1:
        raise ExpressionError(f"{where}: the number of joints must be a positive integer, got {n!r}")
    return _Parser(text, n, where).parse()
