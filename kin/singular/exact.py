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
from kin.singular.solve import display_form, display_text, lambdify_factor, single_joint_solutions
from kin.singular.sympy_model import SympyChain

FORMAT = "rmtkit-singular-exact"
VERSION = 2
#: size limits of a structure (a real chain stays far below them)
MAX_FACTORS = 64
MAX_TERMS = 200_000
MAX_DIGITS = 4000
MAX_NODES = 20_000
MAX_DEPTH = 64
MAX_ROOTS = 1000
_NODE_ARITY = {"add": None, "mul": None, "pow": 2, "sin": 1, "cos": 1}
_LABEL = re.compile(r"^(?:[0-9.]+(?:e[-+]?[0-9]+)?|pi|atan|asin|acos|sqrt|[-+*/() ])+$")
_JOINT_SYMBOL = re.compile(r"^([csq])([1-9][0-9]{0,2})$")
_TREE_SYMBOL = re.compile(r"^([qad])([1-9][0-9]{0,2})$")
_LENGTH_SYMBOL = re.compile(r"^([ad])([1-9][0-9]{0,2})$")
_RATIONAL = re.compile(r"^-?[0-9]{1,%d}(/[1-9][0-9]{0,%d})?$" % (MAX_DIGITS, MAX_DIGITS))


class StructureError(RmtError, ValueError):
    """An exact-analysis structure (worker answer or cache file) is malformed."""


def content_key(robot) -> str:
    """Hash of everything the exact factors and their roots depend on: the chain's frozen DH table,
    joint types, convention, base and tool, task rows, joint limits, and the versions of this format
    and of sympy."""
    chain = robot.chain.frozen()
    content = {"format": FORMAT, "version": VERSION, "sympy": sp.__version__, "convention": chain.convention,
               "types": list(chain.joint_types), "dh": [[repr(float(x)) for x in row] for row in chain.dh_table()],
               "base": [repr(float(x)) for x in chain.base.matrix.ravel()],
               "tool": [repr(float(x)) for x in chain.tool.matrix.ravel()],
               "rows": [int(r) for r in robot.task_rows],
               "limits": [[repr(float(lo)), repr(float(hi))] for lo, hi in zip(chain.lower, chain.upper)]}
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
    chain = robot.chain
    for poly, block in blocks:
        for g, mult in reduce_factors(model, poly):
            terms = []
            if g != 0:
                for monom, coeff in sp.Poly(g, *gens).terms():
                    c = sp.Rational(coeff)
                    terms.append([[[k, int(e)] for k, e in enumerate(monom) if e], f"{c.p}" if c.q == 1
                                  else f"{c.p}/{c.q}"])
            # what the parent would otherwise redo on every call: the display forms (trigsimp) and
            # the roots of one-joint factors (sympy's solve for their exact forms)
            sym_trig = trig_form(g, robot.n)
            num_trig = numeric_form(sym_trig, model.lengths)
            negated = display_text(display_form(num_trig)).startswith("-")   # g and −g: the same zero set
            if negated:
                sym_trig, num_trig = -sym_trig, -num_trig
            joints = [i for i in range(robot.n) if model.q[i] in num_trig.free_symbols]
            roots = None
            if len(joints) == 1:
                j = joints[0]
                fn, _ = lambdify_factor(num_trig, robot.n)
                values, labels = single_joint_solutions(chain, num_trig, j, chain.lower[j], chain.upper[j], fn)
                roots = {"values": [float(v) for v in values], "labels": labels}
            factors.append({"block": block, "multiplicity": int(mult), "terms": terms, "negated": bool(negated),
                            "display": {"num": to_tree(display_form(num_trig)),
                                        "sym": to_tree(display_form(sym_trig))}, "roots": roots})
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
        if not isinstance(f, dict) or set(f) != {"block", "multiplicity", "terms", "negated", "display", "roots"}:
            raise StructureError(f"{where} must have exactly block, multiplicity, terms, negated, display and roots")
        if not isinstance(f["negated"], bool):
            raise StructureError(f"{where}.negated must be true or false")
        disp = f["display"]
        if not isinstance(disp, dict) or set(disp) != {"num", "sym"}:
            raise StructureError(f"{where}.display must have exactly num and sym")
        for k in ("num", "sym"):
            from_tree(disp[k], n, f"{where}.display.{k}")
        roots = f["roots"]
        if roots is not None:
            if not (isinstance(roots, dict) and set(roots) == {"values", "labels"}
                    and isinstance(roots["values"], list) and isinstance(roots["labels"], list)
                    and len(roots["values"]) == len(roots["labels"]) <= MAX_ROOTS):
                raise StructureError(f"{where}.roots must be null or {{values, labels}} of equal length")
            for v in roots["values"]:
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise StructureError(f"{where}.roots.values must be finite numbers")
            for lab in roots["labels"]:
                if not (isinstance(lab, str) and len(lab) <= 200 and _LABEL.match(lab)):
                    raise StructureError(f"{where}.roots.labels must be numbers or pi/atan/asin/acos/sqrt forms")
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
    value}, (q1 … qn)).  No text is evaluated: symbols are made by name, coefficients by Fraction.
    (The display trees and roots are read by the analysis, with :func:`from_tree`.)"""
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


def to_tree(e: sp.Expr) -> list:
    """A display expression as a JSON tree (``["add", …]``, ``["mul", …]``, ``["pow", b, e]``,
    ``["sin", x]``, ``["cos", x]``, ``["sym", "q3"]``, ``["num", "p/q"]``, ``["float", "0.25"]``,
    ``["pi"]``), rebuilt by :func:`from_tree` without parsing any expression text."""
    if e.is_Symbol:
        return ["sym", e.name]
    if e is sp.pi:
        return ["pi"]
    if e.is_Rational:
        return ["num", f"{e.p}" if e.q == 1 else f"{e.p}/{e.q}"]
    if e.is_Float:
        return ["float", repr(float(e))]
    for name, cls in (("add", sp.Add), ("mul", sp.Mul), ("pow", sp.Pow), ("sin", sp.sin), ("cos", sp.cos)):
        if isinstance(e, cls):
            return [name, *[to_tree(a) for a in e.args]]
    raise StructureError(f"cannot store {type(e).__name__} in a display tree")


def from_tree(t, n: int, where: str = "tree") -> sp.Expr:
    """Rebuild (and check) a :func:`to_tree` tree: known node kinds only, symbols q1…qn and length
    symbols a1…/d1…, numbers read by :class:`~fractions.Fraction` or ``float``; at most
    :data:`MAX_NODES` nodes, :data:`MAX_DEPTH` deep."""
    count = [0]

    def build(t, depth):
        count[0] += 1
        if count[0] > MAX_NODES or depth > MAX_DEPTH:
            raise StructureError(f"{where}: more than {MAX_NODES} nodes or deeper than {MAX_DEPTH}")
        if not (isinstance(t, list) and t and isinstance(t[0], str)):
            raise StructureError(f"{where}: a node must be a list starting with its kind")
        kind, args = t[0], t[1:]
        if kind == "sym":
            m = _TREE_SYMBOL.match(args[0]) if len(args) == 1 and isinstance(args[0], str) else None
            if not m or int(m.group(2)) > n:
                raise StructureError(f"{where}: symbol {args!r} is not q1…q{n}, a1…a{n} or d1…d{n}")
            return sp.Symbol(args[0], real=True)
        if kind == "pi" and not args:
            return sp.pi
        if kind == "num" and len(args) == 1 and isinstance(args[0], str) and _RATIONAL.match(args[0]):
            fr = Fraction(args[0])
            return sp.Rational(fr.numerator, fr.denominator)
        if kind == "float" and len(args) == 1 and isinstance(args[0], str) and len(args[0]) <= 40:
            try:
                x = float(args[0])
            except ValueError:
                x = math.nan
            if math.isfinite(x):
                return sp.Float(x, 15)
        if kind in _NODE_ARITY and args and (_NODE_ARITY[kind] is None or len(args) == _NODE_ARITY[kind]):
            sub = [build(a, depth + 1) for a in args]
            return {"add": lambda: sp.Add(*sub), "mul": lambda: sp.Mul(*sub), "pow": lambda: sp.Pow(*sub),
                    "sin": lambda: sp.sin(*sub), "cos": lambda: sp.cos(*sub)}[kind]()
        raise StructureError(f"{where}: node {kind!r} with {len(args)} arguments is not allowed")

    return build(t, 0)


def trig_form(g: sp.Expr, n: int) -> sp.Expr:
    """c_i → cos(q_i), s_i → sin(q_i) (symbols by name, as
    :class:`~kin.singular.sympy_model.SympyChain` makes them)."""
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

