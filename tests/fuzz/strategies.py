"""Hypothesis strategies shared by the fuzz tests: hostile numbers as command-line text and as TOML
values."""
from __future__ import annotations

from hypothesis import strategies as st

#: texts that have broken parsers before: non-finite, huge, tiny, signs, junk
NASTY_TEXT = ["0", "-0", "1", "-1", "0.5", "-2.5", "nan", "inf", "-inf", "1e308", "-1e308", "1e-300", "1e999",
              "0x10", "", " ", "abc", "1e", "--", "1,5", "١", "1_000"]


def mostly(good: st.SearchStrategy, bad: st.SearchStrategy, one_in: int = 12) -> st.SearchStrategy:
    """``good`` except about one time in ``one_in``: files with many fields stay valid often enough
    to reach the code behind the reader."""
    # (hypothesis favours the ends of a range, so the rare branch sits in the middle of a wide one)
    return st.integers(0, 10**6).flatmap(lambda k: bad if k % one_in == 3 else good)


def number_text(lo: float = -10.0, hi: float = 10.0) -> st.SearchStrategy[str]:
    """A command-line number: mostly ordinary, sometimes hostile."""
    return mostly(st.floats(lo, hi, allow_nan=False).map(lambda x: f"{x:.6g}"), st.sampled_from(NASTY_TEXT), 6)


def toml_number(lo: float = -10.0, hi: float = 10.0) -> st.SearchStrategy[str]:
    """A TOML value where a number belongs: mostly ordinary, sometimes hostile (TOML's nan, inf,
    huge, tiny, a string, a boolean, an array)."""
    return mostly(st.floats(lo, hi, allow_nan=False).map(lambda x: repr(float(x))),
                  st.sampled_from(["nan", "inf", "-inf", "1e308", "-1e308", "1e-300", "0", "-0.0", '"1.0"', "true",
                                   "[1.0]", "1e400"]), 20)


def toml_vector(size: int, lo: float = -3.0, hi: float = 3.0) -> st.SearchStrategy[str]:
    """A TOML array of about ``size`` numbers (sometimes the wrong length)."""
    return mostly(st.just(size), st.sampled_from([max(0, size - 1), size + 1]), 20).flatmap(
        lambda k: st.lists(toml_number(lo, hi), min_size=k, max_size=k).map(lambda xs: "[" + ", ".join(xs) + "]"))

