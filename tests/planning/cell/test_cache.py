"""The on-disk cache of mesh enclosures (planning.cell.cache): a second read gives the same spheres
without enclosing again, a changed file or parameter encloses anew, a damaged entry is ignored and
nothing but a regular file is ever replaced."""
from __future__ import annotations

import numpy as np
import pytest

from planning.cell import cache as cell_cache
from planning.cell import load_cell, obstacles

STL = """solid t
facet normal 0 0 1
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 1 0
 endloop
endfacet
facet normal 0 0 1
 outer loop
  vertex 1 0 0
  vertex 1 1 0
  vertex 0 1 0
 endloop
endfacet
endsolid t
"""

CELL = """name = "c"
length_unit = "m"
[[obstacle]]
name = "plate"
type = "mesh"
file = "plate.stl"
scale = {scale}
"""


@pytest.fixture()
def cell_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path / "cache"))
    d = tmp_path / "cell"
    d.mkdir()
    (d / "plate.stl").write_text(STL)
    (d / "cell.toml").write_text(CELL.format(scale=0.5))
    return d


def _spheres(d):
    return load_cell(d / "cell.toml").obstacle("plate").spheres


def test_a_second_read_takes_the_spheres_from_the_cache(cell_dir, monkeypatch):
    first = _spheres(cell_dir)
    entries = list((cell_dir.parent / "cache" / "cells").glob("*.npz"))
    assert len(entries) == 1

    def refuse(*a, **k):
        raise AssertionError("enclosed again although the cache holds it")

    monkeypatch.setattr(obstacles, "enclose_triangles", refuse)
    assert np.array_equal(_spheres(cell_dir), first)
    # the spheres hold every triangle of the (scaled) plate: independent of the cache
    corners = np.array([[0, 0, 0], [0.5, 0, 0], [0, 0.5, 0], [0.5, 0.5, 0]])
    d = np.linalg.norm(corners[:, None, :] - first[None, :, :3], axis=2) - first[None, :, 3]
    assert (d.min(axis=1) <= 1e-12).all()


def test_a_changed_file_or_parameter_encloses_anew(cell_dir):
    a = _spheres(cell_dir)
    (cell_dir / "cell.toml").write_text(CELL.format(scale=2.0))
    b = _spheres(cell_dir)
    assert b[:, :3].max() > a[:, :3].max() * 3
    (cell_dir / "plate.stl").write_text(STL.replace("vertex 1 1 0", "vertex 1 1 0.5"))
    c = _spheres(cell_dir)
    assert not np.array_equal(b, c)
    assert len(list((cell_dir.parent / "cache" / "cells").glob("*.npz"))) == 3


def test_a_damaged_entry_is_ignored_and_a_non_file_never_replaced(cell_dir):
    good = _spheres(cell_dir)
    (entry,) = (cell_dir.parent / "cache" / "cells").glob("*.npz")
    entry.write_bytes(b"not an npz")
    assert np.array_equal(_spheres(cell_dir), good)
    entry.unlink()
    entry.mkdir()                                     # something else took the path
    assert np.array_equal(_spheres(cell_dir), good)
    assert entry.is_dir()


def test_the_key_depends_on_every_input():
    k1 = cell_cache.cache_key("mesh.stl", b"x", [1.0], np.eye(4))
    assert k1 == cell_cache.cache_key("mesh.stl", b"x", [1.0], np.eye(4))
    assert k1 != cell_cache.cache_key("mesh.stl", b"y", [1.0], np.eye(4))
    assert k1 != cell_cache.cache_key("mesh.stl", b"x", [1.0 + 1e-12], np.eye(4))
    assert k1 != cell_cache.cache_key("mesh.obj", b"x", [1.0], np.eye(4))
