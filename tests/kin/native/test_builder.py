"""kin.native.builder (:func:`kin.native.build`): the one helper that compiles and caches kernels —
a second call loads the cached library; two processes building at once compile once and both load the result; a compiler
error is one line of CompileError; a path taken by something other than a regular file is never
replaced; the native build falls back to the portable one; one time-out."""
from __future__ import annotations

import ctypes
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import kin
from kin.native import NATIVE_TIMEOUT, Header, build, find_compiler
from kin.native import builder as build_module

PROBE = Path(__file__).resolve().with_name("probe.c")
ROOT = Path(__file__).resolve().parents[3]

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler")


def header(value: int = 41) -> str:
    return Header("probe").define("PROBE_VALUE", value).text()


def probe_value(path: Path) -> int:
    return ctypes.CDLL(str(path)).rmt_probe_value()


def wrapper(tmp_path: Path, body: str, name: str = "cc") -> str:
    """A compiler script that logs each run (one line of arguments) and then does ``body``."""
    log = tmp_path / f"{name}.log"
    script = tmp_path / name
    script.write_text(f'#!/bin/sh\necho "$*" >> {log}\n{body}\n')
    script.chmod(0o755)
    return str(script)


def compiles(tmp_path: Path, name: str = "cc") -> list[str]:
    """The logged runs of the wrapper that compiled (not ``--version``)."""
    log = tmp_path / f"{name}.log"
    return [ln for ln in log.read_text().splitlines() if "-shared" in ln] if log.exists() else []


def test_second_call_loads_the_cached_library(tmp_path):
    a = build("probe", PROBE, header(), directory=tmp_path)
    assert not a.cached and a.path.parent == tmp_path and a.path.suffix == ".so"
    assert a.path.name.startswith(f"probe_{a.arch}-")
    assert probe_value(a.path) == 41
    mtime = a.path.stat().st_mtime_ns
    b = build("probe", PROBE, header(), directory=tmp_path)
    assert b.cached and b.path == a.path and b.path.stat().st_mtime_ns == mtime
    c = build("probe", PROBE, header(42), directory=tmp_path)  # another generated header: another library
    assert not c.cached and c.path != a.path and probe_value(c.path) == 42
    d = build("probe", PROBE, header(), flags=["-DUNUSED=1"], directory=tmp_path)  # other flags: another one
    assert not d.cached and d.path not in (a.path, c.path)
    assert sorted(p.suffix for p in tmp_path.iterdir()) == [".so"] * 3  # no lock file or build directory left


def test_default_directory_is_native_under_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("RMTKIT_CACHE", str(tmp_path))
    lib = build("probe", PROBE, header())
    assert lib.path.parent == tmp_path / "native"
    assert lib.module_name == lib.path.stem.replace("-", "_") and lib.module_name.isidentifier()


_RACE = textwrap.dedent("""
    import ctypes, sys, time
    from pathlib import Path
    from kin.native import Header, build
    start = float(sys.argv[3])
    while time.time() < start:
        time.sleep(0.001)
    lib = build("probe", Path(sys.argv[1]), Header("probe").define("PROBE_VALUE", 7).text(),
                directory=Path(sys.argv[2]))
    print(lib.cached, ctypes.CDLL(str(lib.path)).rmt_probe_value(), lib.path)
""")


def test_two_processes_building_at_once_make_one_library(tmp_path):
    cc = wrapper(tmp_path, f'sleep 1\nexec {find_compiler()} "$@"')  # a slow compiler: the builds overlap
    libs = tmp_path / "libs"
    env = {**os.environ, "RMTKIT_CC": cc, "PYTHONPATH": str(ROOT)}
    import time
    start = f"{time.time() + 2.0:.3f}"
    procs = [subprocess.Popen([sys.executable, "-c", _RACE, str(PROBE), str(libs), start], env=env, text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1] for o in outs]
    lines = sorted(o[0].split() for o in outs)
    assert [ln[0] for ln in lines] == ["False", "True"]  # one compiled, the other waited and loaded it
    assert [ln[1] for ln in lines] == ["7", "7"] and lines[0][2] == lines[1][2]
    assert len(compiles(tmp_path)) == 1
    assert [p.name for p in libs.iterdir()] == [Path(lines[0][2]).name]


def test_a_compiler_error_is_one_line(tmp_path):
    with pytest.raises(kin.CompileError) as e:
        build("probe", PROBE, "/* PROBE_VALUE missing */\n", arch="portable", directory=tmp_path)
    msg = str(e.value)
    assert "\n" not in msg and "error" in msg and "PROBE_VALUE" in msg and "probe" in msg
    assert list(tmp_path.iterdir()) == []  # nothing cached, no build directory or lock file left


def test_the_first_error_line_is_reported(tmp_path):
    cc = wrapper(tmp_path, "echo 'In file included from x.c:1:' >&2\necho 'x.c:3:1: error: no good' >&2\n"
                           "echo '   3 | oops' >&2\necho 'compilation terminated.' >&2\nexit 1")
    with pytest.raises(kin.CompileError,
                       match=r"^cc \(portable build\) failed on the probe: x\.c:3:1: error: no good$"):
        build("probe", PROBE, header(), arch="portable", compiler=cc, directory=tmp_path, what="the probe")
    silent = wrapper(tmp_path, "exit 3", name="silent")
    with pytest.raises(kin.CompileError, match="exit status 3$"):
        build("probe", PROBE, header(), arch="portable", compiler=silent, directory=tmp_path)


def test_a_refused_native_build_becomes_portable(tmp_path):
    cc = wrapper(tmp_path, 'for a in "$@"; do [ "$a" = -march=native ] && '
                           '{ echo "error: bad -march" >&2; exit 1; }; done\n'
                           f'exec {find_compiler()} "$@"')
    lib = build("probe", PROBE, header(), arch="native", compiler=cc, directory=tmp_path)
    assert lib.arch == "portable" and "_portable-" in lib.path.name and probe_value(lib.path) == 41
    assert [("-march=native" in ln) for ln in compiles(tmp_path)] == [True, False]


def test_one_time_out_and_no_retry_after_it(tmp_path, monkeypatch):
    assert NATIVE_TIMEOUT == 300
    monkeypatch.setattr(build_module, "NATIVE_TIMEOUT", 0.5)
    cc = wrapper(tmp_path, "sleep 5")
    with pytest.raises(kin.CompileError, match="took over"):
        build("probe", PROBE, header(), arch="native", compiler=cc, directory=tmp_path)
    assert len(compiles(tmp_path)) == 1  # a time-out is not retried as a portable build


@pytest.mark.parametrize("kind", ["directory", "dangling symlink", "fifo"])
def test_a_path_that_is_not_a_regular_file_is_never_replaced(tmp_path, kind):
    lib = build("probe", PROBE, header(), directory=tmp_path)
    lib.path.unlink()
    if kind == "directory":
        lib.path.mkdir()
        (lib.path / "keep").write_text("mine")
    elif kind == "dangling symlink":
        lib.path.symlink_to(tmp_path / "nowhere")
    else:
        os.mkfifo(lib.path)
    with pytest.raises(kin.CompileError, match="not a regular file"):
        build("probe", PROBE, header(), directory=tmp_path)
    if kind == "directory":
        assert lib.path.is_dir() and (lib.path / "keep").read_text() == "mine"
    elif kind == "dangling symlink":
        assert lib.path.is_symlink() and os.readlink(lib.path) == str(tmp_path / "nowhere")
    else:
        assert lib.path.is_fifo()


def test_without_a_compiler(monkeypatch, tmp_path):
    monkeypatch.setenv("RMTKIT_CC", "none")
    with pytest.raises(kin.CompileError, match="no C compiler"):
        build("probe", PROBE, header(), directory=tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_parallel_for_covers_the_range_once(tmp_path):
    f = ctypes.CDLL(str(build("probe", PROBE, header(), directory=tmp_path).path)).rmt_probe_sum
    f.argtypes = [ctypes.c_longlong, ctypes.c_int, ctypes.POINTER(ctypes.c_int)]
    f.restype = ctypes.c_longlong
    ran = ctypes.c_int()
    for n, threads, expect in ((100_003, 3, 3), (100_003, 1, 1), (100_003, 0, 1), (5, 2, 2), (0, 4, 4),
                               (1_000, 1_000, 256)):
        assert f(n, threads, ctypes.byref(ran)) == n * (n - 1) // 2
        assert ran.value == expect
