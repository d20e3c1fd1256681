"""Swaps between assemblies (design.compose.edits): the edit script is as short as a brute-force
search over single operations finds, carrying it out gives the target, and it reads as swaps."""
from __future__ import annotations

import itertools
import math
from collections import deque
from pathlib import Path

import numpy as np

from design.compose.edits import apply_script, edit_script, swaps
from kin.modules import Assembly, load_catalogue

CATALOGUE = Path(__file__).resolve().parents[2] / "kin" / "modules" / "small_catalogue.toml"
Q = math.pi / 2
BASES = (("B1", None), ("B2", None))
MODULES = (("a", 0.0), ("a", Q), ("b", 0.0), ("b", Q))
MAX_LEN = 4                 # base + up to three modules


def _bfs(start: tuple) -> dict:
    """Least number of single operations (insert, delete or substitute one token: a (name, twist)
    pair, a substitution within one name being the re-mount) from ``start`` to every sequence of at
    most MAX_LEN tokens over the alphabet."""
    alphabet = BASES + MODULES
    dist = {start: 0}
    todo = deque([start])
    while todo:
        s = todo.popleft()
        nxt = []
        for i in range(len(s)):
            nxt.append(s[:i] + s[i + 1:])
            nxt.extend(s[:i] + (c,) + s[i + 1:] for c in alphabet if c != s[i])
        if len(s) < MAX_LEN:
            nxt.extend(s[:i] + (c,) + s[i:] for i in range(len(s) + 1) for c in alphabet)
        for t in nxt:
            if t not in dist:
                dist[t] = dist[s] + 1
                todo.append(t)
    return dist


def _assembly(seq: tuple) -> Assembly:
    return Assembly(tuple(n for n, _ in seq), tuple(t for _, t in seq[1:]))


def _all_assemblies():
    for base in BASES:
        for n in range(MAX_LEN):
            for rest in itertools.product(MODULES, repeat=n):
                yield (base, *rest)


def test_edit_count_is_the_least_a_brute_force_search_finds():
    rng = np.random.default_rng(7)
    every = list(_all_assemblies())
    sources = [every[i] for i in rng.choice(len(every), 25, replace=False)]
    checked = 0
    for src in sources:
        dist = _bfs(src)
        a = _assembly(src)
        for tgt in every:
            b = _assembly(tgt)
            script = edit_script(a, b)
            assert len(script) == dist[tgt] == swaps(a, b), (src, tgt, script)
            assert apply_script(a, script) == b, (src, tgt, script)
            checked += 1
    assert checked == 25 * len(every)


def test_swaps_read_as_replace_add_remove_and_turn():
    cat = load_catalogue(CATALOGUE)
    a = Assembly.parse("B JS LS JL JL T", cat)
    b = Assembly.parse("B JS LL JL@90 T", cat)
    text = [e.text(cat, a, b) for e in edit_script(a, b, cat)]
    assert sorted(text) == sorted(["replace link LS by LL", "turn JL to 90°", "remove joint JL (2nd)"]) or \
        sorted(text) == sorted(["replace link LS by LL", "remove joint JL (1st)", "turn JL to 90°"])
    c = Assembly.parse("B JS LS JL LE@180 JL T", cat)
    assert [e.text(cat, a, c) for e in edit_script(a, c, cat)] == ["add link LE at 180° after JL (1st)"]
    assert edit_script(a, a, cat) == []


def test_a_link_is_replaced_by_a_link_where_a_joint_would_do_as_well():
    cat = load_catalogue(CATALOGUE)
    a = Assembly.parse("B JS LS JL T", cat)
    b = Assembly.parse("B JS JL LL T", cat)
    # two swaps either way: (LS→JL, JL→LL) crosses kinds twice; (remove LS, add LL) crosses none
    script = edit_script(a, b, cat)
    assert len(script) == 2
    assert [e.op for e in script if e.op == "replace"] == []
