"""The exact part of the singularity analysis as plain data: det J factored (sympy) into
polynomials in c_i = cos q_i, s_i = sin q_i, prismatic q_i and link-length symbols, written as
sparse monomial lists with rational coefficients.

This form is what the budgeted worker (:mod:`kin.singular.budget`) answers and what the disk cache
(:mod:`kin.singular.cache`) stores.  It is rebuilt into sympy expressions without parsing any
expression text: symbol names are checked against ``c7``/``s7``/``q7``/``a2``/``d4`` patterns,
coefficients are integers or fractions read by :class:`fractions.Fraction`, and every field is
type- and range-checked (:func:`validate_structure`); anything else is refused.
"""
from __future__ import annotations

import hashlib
import json
import math
import re
from fractions import Fraction

import sympy as sp

from kin.errors import RmtError
from kin.singular.determinant import BLOCKS, SPLITS, det_and_blocks, reduce_factors
from kin.singular.sympy_model import SympyChain

FORMAT = "rmtkit-singular-exact"
VERSION = 1
#: size limits of a structure (a real chain stays far below them)
MAX_FACTORS = 64
MAX_TERMS = 200_000
MAX_DIGITS = 4000
_JOINT_SYMBOL = re.compile(r"^([csq])([1-9][0-9]{0,2})$")
_LENGTH_SYMBOL = re.compile(r"^([ad])([1-9][0-9]{0,2})$")
_RATIONAL = re.compile(r"^-?[0-9]{1,%d}(/[1-9][0-9]{0,%d})?$" % (MAX_DIGITS, MAX_DIGITS))


class StructureError(RmtError, ValueError):
    """An exact-analysis structure (worker answer or cache file) is malformed."""


def content_key(robot) -> str:
    """Hash of everything the exact factors depend on: the chain's frozen DH table, joint types,
    convention, base and tool, task rows, and the versions of this format and of sympy."""
    chain = robot.chain.frozen()
    content = {"format": FORMAT, "version": VERSION, "sympy": sp.__version__, "convention": chain.convention,
               "types": list(chain.joint_types), "dh": [[repr(float(x)) for x in row] for row in chain.dh_table()],
               "base": [repr(float(x)) for x in chain.base.matrix.ravel()],
               "tool": [repr(float(x)) for x in chain.tool.matrix.ravel()],
               "rows": [int(r) for r in robot.task_rows]}
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()[:24]


def _generators(n: int, lengths) -> list[str]:
    return ([f"c{i}" for i in range(1, n + 1)] + [f"s{i}" for i in range(1, n + 1)]
            + [f"q{i}" for i in range(1, n + 1)] + sorted(lengths))


def exact_structure(robot) -> dict:
    """Compute and factor det J of ``robot`` (slow: run it under a budget) → plain JSON data."""
    model = SympyChain(robot.chain, keep_lengths=True)
    blocks, split, rows, numeric = det_and_blocks(robot, model)
    lengths = {str(k): float(v) for k, v in model.lengths.items()}
    gens_names = _generators(robot.n, lengths)
    by_name = {str(s): s for s in (*model.c, *model.s, *model.q, *model.lengths)}
    gens = [by_name[g] for g in gens_names]
    factors = []
    for poly, block in blocks:
        for g, mult in reduce_factors(model, poly):
            terms = []
            if g != 0:
                for monom, coeff in sp.Poly(g, *gens).terms():
                    c = sp.Rational(coeff)
                    terms.append([[[k, int(e)] for k, e in enumerate(monom) if e], f"{c.p}" if c.q == 1
                                  else f"{c.p}/{c.q}"])
            factors.append({"block": block, "multiplicity": int(mult), "terms": terms})
    return {"format": FORMAT, "version": VERSION, "n": robot.n, "split": split, "lengths_numeric": bool(numeric),
            "rows": [int(r) for r in rows], "lengths": lengths, "generators": gens_names, "factors": factors}


def _int(x, field: str, lo: int, hi: int) -> int:
    if isinstance(x, bool) or not isinstance(x, int) or not lo <= x <= hi:
        raise StructureError(f"{field} must be an integer in [{lo}, {hi}]")
    return x


def validate_structure(d, n: int, rows: tuple[int, ...]) -> dict:
    """Check a structure for a chain of ``n`` joints controlling ``rows``; raise
    :class:`StructureError` naming the first bad field.  Returns ``d`` unchanged."""
    if not isinstance(d, dict):
        raise StructureError("structure must be a JSON object")
    if d.get("format") != FORMAT or d.get("version") != VERSION:
        raise StructureError(f"format must be {FORMAT!r} version {VERSION}")
    _int(d.get("n"), "n", n, n)
    if d.get("split") not in SPLITS:
        raise StructureError(f"split must be one of {', '.join(SPLITS)}")
    if not isinstance(d.get("lengths_numeric"), bool):
        raise StructureError("lengths_numeric must be true or false")
    if d.get("rows") != list(rows):
        raise StructureError(f"rows must be {list(rows)}")
    lengths = d.get("lengths")
    if not isinstance(lengths, dict) or len(lengths) > 2 * n:
        raise StructureError("lengths must be an object of at most 2n entries")
    for k, v in lengths.items():
        m = _LENGTH_SYMBOL.match(k)
        if not m or int(m.group(2)) > n:
            raise StructureError(f"lengths: {k!r} is not a length symbol a1…a{n} or d1…d{n}")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v == 0:
            raise StructureError(f"lengths.{k} must be a finite non-zero number")
    gens = _generators(n, lengths)
    if d.get("generators") != gens:
        raise StructureError("generators must be c1…cn, s1…sn, q1…qn and the length symbols in order")
    factors = d.get("factors")
    if not isinstance(factors, list) or len(factors) > MAX_FACTORS:
        raise StructureError(f"factors must be a list of at most {MAX_FACTORS}")
    total = 0
    for i, f in enumerate(factors):
        where = f"factors[{i}]"
        if not isinstance(f, dict) or set(f) != {"block", "multiplicity", "terms"}:
            raise StructureError(f"{where} must have exactly block, multiplicity and terms")
        if f["block"] not in BLOCKS:
            raise StructureError(f"{where}.block must be one of {', '.join(BLOCKS)}")
        _int(f["multiplicity"], f"{where}.multiplicity", 1, 1000)
        terms = f["terms"]
        if not isinstance(terms, list):
            raise StructureError(f"{where}.terms must be a list")
        total += len(terms)
        if total > MAX_TERMS:
            raise StructureError(f"more than {MAX_TERMS} terms in all")
        for t in terms:
            if not (isinstance(t, list) and len(t) == 2 and isinstance(t[0], list) and isinstance(t[1], str)
                    and _RATIONAL.match(t[1])):
                raise StructureError(f"{where}.terms: each term must be [[[generator, exponent], …], \"p/q\"]")
            seen = set()
            for pair in t[0]:
                if not (isinstance(pair, list) and len(pair) == 2):
                    raise StructureError(f"{where}.terms: a power must be [generator index, exponent]")
                k = _int(pair[0], f"{where}.terms generator", 0, len(gens) - 1)
                _int(pair[1], f"{where}.terms exponent", 1, 64)
                if k in seen:
                    raise StructureError(f"{where}.terms: generator {k} repeated in one monomial")
                seen.add(k)
    return d


def rebuild(d: dict) -> tuple[list[tuple[sp.Expr, int, str]], dict[sp.Symbol, float], tuple[sp.Symbol, ...]]:
    """A validated structure → ([(g in c, s, q and lengths, multiplicity, block)], {length symbol:
    value}, (q1 … qn)).  No text is evaluated: symbols are made by name, coefficients by Fraction."""
    n = d["n"]
    syms = [sp.Symbol(name, real=True) for name in d["generators"]]
    out = []
    for f in d["factors"]:
        terms = []
        for powers, coeff in f["terms"]:
            fr = Fraction(coeff)
            terms.append(sp.Mul(sp.Rational(fr.numerator, fr.denominator),
                                *[syms[k] ** e for k, e in powers]))
        out.append((sp.Add(*terms), f["multiplicity"], f["block"]))
    lengths = {syms[3 * n + i]: float(d["lengths"][name]) for i, name in enumerate(d["generators"][3 * n:])}
    return out, lengths, tuple(syms[2 * n:3 * n])


def trig_form(g: sp.Expr, n: int) -> sp.Expr:
    """c_i → cos(q_i), s_i → sin(q_i) (symbols by name, as :class:`~kin.singular.sympy_model.SympyChain` makes them)."""
    sub = {}
    for i in range(1, n + 1):
        q = sp.Symbol(f"q{i}", real=True)
        sub[sp.Symbol(f"c{i}", real=True)] = sp.cos(q)
        sub[sp.Symbol(f"s{i}", real=True)] = sp.sin(q)
    return g.subs(sub)


def numeric_form(expr: sp.Expr, lengths: dict[sp.Symbol, float]) -> sp.Expr:
    """Length symbols → exact rationals of their values (as :meth:`SympyChain.numeric`)."""
    from kin.singular.sympy_model import rational
    return expr.subs({k: rational(v) for k, v in lengths.items()})

