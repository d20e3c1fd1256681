"""The output writer: only regular files are replaced, parents are created, a failed write leaves the
old content and no temporary file; a run directory replaces the old one only when complete."""
from __future__ import annotations

import os
import stat

import pytest

from kin.output import OutputError, check_output, fresh_directory, write_output


def _tree(root):
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


def test_writes_and_replaces_a_regular_file(tmp_path):
    p = tmp_path / "a.txt"
    write_output(p, "one")
    write_output(p, b"two")
    write_output(p, lambda fh: fh.write(b"three"))
    assert p.read_text() == "three"
    assert _tree(tmp_path) == ["a.txt"]
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~umask


def test_creates_missing_parents(tmp_path):
    p = tmp_path / "x" / "y" / "a.json"
    write_output(p, "{}")
    assert p.read_text() == "{}"


def test_refuses_a_symlink_and_leaves_its_target(tmp_path):
    target = tmp_path / "target.txt"
    target.write_text("keep")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    with pytest.raises(OutputError, match="symbolic link"):
        write_output(link, "new")
    assert target.read_text() == "keep" and link.is_symlink()


def test_refuses_a_directory_a_fifo_and_a_device(tmp_path):
    (tmp_path / "d").mkdir()
    with pytest.raises(OutputError, match="is a directory"):
        write_output(tmp_path / "d", "x")
    fifo = tmp_path / "f"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match="FIFO"):
        write_output(fifo, "x")                         # must not block opening the FIFO either
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    if os.path.exists("/dev/null"):
        with pytest.raises(OutputError, match="character device"):
            check_output("/dev/null")
    assert _tree(tmp_path) == ["d", "f"]


def test_a_name_ending_in_a_slash_is_a_directory(tmp_path):
    with pytest.raises(OutputError, match="names a directory"):
        write_output(f"{tmp_path}/new/", "x")
    assert _tree(tmp_path) == []


def test_parent_that_is_a_file(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.raises(OutputError, match="is not a directory"):
        write_output(tmp_path / "file" / "sub" / "a.txt", "x")


def test_failure_keeps_old_content_and_removes_the_temporary(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")

    def boom(fh):
        fh.write(b"partial")
        raise RuntimeError("writer failed")
    with pytest.raises(RuntimeError):
        write_output(p, boom)
    assert p.read_text() == "old" and _tree(tmp_path) == ["a.txt"]
    with pytest.raises(KeyboardInterrupt):
        write_output(p, lambda fh: (_ for _ in ()).throw(KeyboardInterrupt()))
    assert p.read_text() == "old" and _tree(tmp_path) == ["a.txt"]


def test_fresh_directory_replaces_only_when_complete(tmp_path):
    run = tmp_path / "out" / "study"
    with fresh_directory(run, ["results.json", "plot.png"]) as d:
        (d / "results.json").write_text("1")
        (d / "plot.png").write_text("p1")
    assert _tree(run) == ["plot.png", "results.json"]
    with pytest.raises(KeyboardInterrupt):
        with fresh_directory(run, ["results.json", "plot.png"]) as d:
            (d / "plot.png").write_text("p2")           # a new plot …
            raise KeyboardInterrupt                      # … then the run is interrupted
    assert (run / "plot.png").read_text() == "p1" and (run / "results.json").read_text() == "1"
    assert _tree(tmp_path / "out") == ["study", "study/plot.png", "study/results.json"]
    with fresh_directory(run, ["results.json", "plot.png"]) as d:
        (d / "results.json").write_text("2")
    assert _tree(run) == ["results.json"] and (run / "results.json").read_text() == "2"
    assert _tree(tmp_path / "out") == ["study", "study/results.json"]


def test_fresh_directory_never_deletes_foreign_files(tmp_path):
    run = tmp_path / "study"
    run.mkdir()
    (run / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="notes.txt"):
        with fresh_directory(run, ["results.json"]):
            pass
    assert (run / "notes.txt").read_text() == "mine"
    (tmp_path / "plain").write_text("")
    with pytest.raises(OutputError, match="must be a directory"):
        with fresh_directory(tmp_path / "plain", ["results.json"]):
            pass
