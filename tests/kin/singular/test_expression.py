"""The safe factor-expression reader: the same expressions as sympy's own parser for the grammar's
texts (including every factor of the bundled robots), evaluated against a plain numpy formula, and a
one-line error with the position for anything else — no Python is ever run."""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from kin.singular.expression import ExpressionError, joint_symbols, parse_expression

Q = joint_symbols(6)
NAMES = {f"q{i + 1}": Q[i] for i in range(6)}

# texts of the grammar (the second column: the same text for sympy's trusted parser)
GOOD = [
    ("sin(q5)", "sin(q5)"),
    ("0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15",
     "0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15"),
    ("-q1**2", "-q1**2"),
    ("q1^2 - 3*q2/4", "q1**2 - 3*q2/4"),
    ("2^3^2*q1", "2**9*q1"),                    # right-associative
    ("q3**(-2) + q4^-1", "q3**(-2) + 1/q4"),
    ("1e-5*q1 - .5*q2 + 3.*q3", "1e-5*q1 - 0.5*q2 + 3.0*q3"),
    ("−q1×2÷4", "-q1/2"),
    ("--q1 + +q2", "q1 + q2"),
    ("sin(cos(q1)*(q2 - 1))^2", "sin(cos(q1)*(q2 - 1))**2"),
]


@pytest.mark.parametrize("text,trusted", GOOD)
def test_same_expression_as_sympys_parser(text, trusted):
    e = parse_expression(text, 6)
    ref = sp.sympify(trusted, locals=NAMES)          # trusted text written here, not user input
    assert sp.simplify(e - ref) == 0
    f, g = sp.lambdify([Q], e, "numpy"), sp.lambdify([Q], ref, "numpy")
    X = np.random.default_rng(0).uniform(0.2, 1.5, (50, 6))
    assert np.allclose(f(X.T), g(X.T), rtol=1e-12)


def test_value_against_numpy():
    e = parse_expression("0.27*sin(q2) + 0.07*sin(q2 + q3) + 0.302*cos(q2 + q3)", 6)
    q = np.array([0.1, -0.4, 1.1, 0.0, 0.3, 0.0])
    ref = 0.27 * math.sin(q[1]) + 0.07 * math.sin(q[1] + q[2]) + 0.302 * math.cos(q[1] + q[2])
    assert float(e.subs(dict(zip(Q, q)))) == pytest.approx(ref, rel=1e-14)


def test_every_bundled_factor_text_parses():
    """Factors as the analysis prints them (sympy's str) — what `rmt windows --out` saves."""
    texts = ["2025*sin(q2)*sin(q3)**2*sin(q5) - 20700*sin(q2)*sin(q3)**2*cos(q5) - 17865*sin(q2)*sin(q3)*"
             "sin(q4)*sin(q5)*cos(q3)", "0.02032*sin(q3) + 0.43307*cos(q3)", "q3", "sin(q2)"]
    for t in texts:
        assert str(parse_expression(t, 6)) == str(sp.sympify(t, locals=NAMES))


BAD = [
    ("__import__('os').system('touch X')", "unexpected character"),
    ("q1.real", "unexpected character '.'"),
    ("q7", "out of range"),
    ("q0", "unknown name"),
    ("exp(q1)", "unknown name"),
    ("sin q1", "expected '('"),
    ("(q1 + 1", "expected ')'"),
    ("q1 q2", "expected an operator"),
    ("", "expected a number"),
    ("1/0", "division by zero"),
    ("q1/(2-2)", "division by zero"),
    ("q1**q2", "exponent must be a constant integer"),
    ("2^100000", "exponent must be a constant integer"),
    ("q1^0.5", "exponent must be a constant integer"),
    ("1e999*q1", "not a finite double"),
    ("10.0^60^1*1e300", "not a finite number"),
    ("(" * 200 + "q1" + ")" * 200, "nested deeper"),
    ("lambda: 0", "unexpected character ':' at position 7"),
]


@pytest.mark.parametrize("text,msg", BAD)
def test_refused_with_position(text, msg):
    with pytest.raises(ExpressionError, match=re.escape(msg)) as e:
        parse_expression(text, 6, "f.json: expr")
    s = str(e.value)
    assert "\n" not in s and s.startswith("f.json: expr") and "position" in s


def test_position_is_the_offending_character():
    with pytest.raises(ExpressionError, match="at position 9;"):
        parse_expression("q1 + q2 $ 3", 6)
    with pytest.raises(ExpressionError, match=r"position 6 \(found 'q9'\)"):
        parse_expression("q1 + q9", 6)


def test_no_code_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for t in ["__import__('os').system('touch X')", "exec('open(\"X\",\"w\")')", "q1.__class__"]:
        with pytest.raises(ExpressionError):
            parse_expression(t, 6)
    assert not Path("X").exists()


def test_non_string_and_bad_n():
    with pytest.raises(ExpressionError, match="must be a string"):
        parse_expression(3, 6)
    with pytest.raises(ExpressionError, match="positive integer"):
        parse_expression("q1", 0)
