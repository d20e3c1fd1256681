"""C lives in .c/.h files: no Python source of the four layers holds C code in a string.

Every string literal (docstrings included) of every module under kin/, planning/, design/ and
studies/ is searched for what only C source contains.  The one writer of C text is
kin/native/header.py, and it writes numbers and tables only: ``#define`` appears in the code of
no other module.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
LAYERS = ["kin", "planning", "design", "studies"]
C_MARKERS = re.compile(r"#\s*include\b|#\s*pragma\b|_Pragma\s*\(|__global__|static\s+inline\b|__attribute__\s*\(|"
                       r"typedef\s+struct\b|for\s*\(\s*int\b|PyMODINIT_FUNC|\bRMT_INLINE\b")
HEADER_WRITER = ROOT / "kin" / "native" / "header.py"
SOURCES = sorted(p for top in LAYERS for p in (ROOT / top).rglob("*.py"))


def _strings(tree: ast.AST) -> tuple[list[str], list[str]]:
    """(docstrings, other string constants) of a module."""
    docs = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
                    and isinstance(first.value.value, str)):
                docs.add(id(first.value))
    doc, code = [], []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            (doc if id(node) in docs else code).append(node.value)
    return doc, code


def test_the_search_sees_the_project():
    names = {p.relative_to(ROOT).as_posix() for p in SOURCES}
    assert {"kin/compiled/evaluator.py", "kin/ik/compiled.py", "planning/timing/native.py"} <= names
    assert C_MARKERS.search('#include <math.h>') and C_MARKERS.search("static inline void f(void)")
    assert (ROOT / "kin" / "compiled" / "kernel.c").is_file() and (ROOT / "kin" / "ik" / "ik.c").is_file()
    assert (ROOT / "planning" / "timing" / "reach.c").is_file()


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_c_in_python_strings(path):
    doc, code = _strings(ast.parse(path.read_text(), filename=str(path)))
    found = [s for s in doc + code if C_MARKERS.search(s)]
    assert not found, f"{path.relative_to(ROOT)} holds C in a string: {found[0][:120]!r}"
    if path != HEADER_WRITER:
        defines = [s for s in code if re.search(r"#\s*define\b", s)]
        assert not defines, (f"{path.relative_to(ROOT)} writes C (#define) outside kin/native/header.py: "
                             f"{defines[0][:120]!r}")
