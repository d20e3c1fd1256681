"""Tests of planning.timing.native: compiled on first use into the cache directory under a hash of
the source, loaded from there afterwards, and absent (None) when compiling is disabled."""
from __future__ import annotations

import numpy as np
import pytest

import planning.timing.native as native
from kin.native import find_compiler
from planning.timing import time_parameterize


def test_compiles_once_into_the_cache_and_loads_from_it(tmp_path, monkeypatch):
    if find_compiler() is None:
        pytest.skip("no C compiler (RMTKIT_CC=none or none installed)")
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    monkeypatch.setattr(native, "_loaded", {})
    f = native.load_reach()
    assert f is not None
    libs = sorted((tmp_path / "native").glob("timing_reach_*.so"))
    assert len(libs) == 1
    mtime = libs[0].stat().st_mtime_ns
    monkeypatch.setattr(native, "_loaded", {})           # a new process: loads, does not recompile
    assert native.load_reach() is not None
    assert libs[0].stat().st_mtime_ns == mtime and len(list((tmp_path / "native").glob("*.so"))) == 1
    tr = time_parameterize(np.array([[0.0, 0.0], [1.0, 0.5], [1.5, 1.5]]), 1.0, 2.0)
    assert "(c)" in tr.qp_status


def test_disabled_compiler_gives_none_and_numpy(monkeypatch):
    monkeypatch.setenv("RMTKIT_CC", "none")
    assert native.load_reach() is None
    tr = time_parameterize(np.array([[0.0], [1.0]]), 1.0, 2.0)
    assert "numpy" in tr.qp_status
    assert tr.duration == pytest.approx(1.5, rel=1e-2)     # trapezoid: L/v + v/a


def test_a_broken_compiler_falls_back_with_a_warning(tmp_path, monkeypatch):
    fake = tmp_path / "cc"
    fake.write_text("#!/bin/sh\necho 'fake compiler failed' >&2\nexit 1\n")
    fake.chmod(0o755)
    monkeypatch.setenv("RMTKIT_CC", str(fake))
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(native, "_loaded", {})
    with pytest.warns(RuntimeWarning, match="compiling the timing passes failed"):
        assert native.load_reach() is None
