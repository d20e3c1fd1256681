"""The entry point: start-up imports only what a command needs, and Ctrl-C anywhere — while the
command line starts or while a command runs — prints one line and exits 130, without a traceback."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from studies.cli import main
from studies.cli.follow import MODES

ROOT = Path(__file__).resolve().parents[3]
HEAVY = ("casadi", "ompl", "sympy", "matplotlib", "osqp", "scipy", "sklearn", "design")


def _modules_after(argv: list[str]) -> tuple[set[str], str]:
    code = ("import sys, contextlib, io\nfrom studies.cli import main\n"
            "out = io.StringIO()\n"
            "with contextlib.redirect_stdout(out):\n"
            "    try:\n        main(%r)\n    except SystemExit:\n        pass\n"
            "print(' '.join(m for m in %r if m in sys.modules))\n" % (argv, HEAVY))
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert p.returncode == 0, p.stderr
    return set(p.stdout.split()), p.stderr


def test_help_imports_no_heavy_dependency():
    loaded, _ = _modules_after(["--help"])
    assert loaded == set()
    loaded, _ = _modules_after(["plan", "--help"])
    assert loaded == set()


def test_fk_imports_casadi_only():
    loaded, err = _modules_after(["fk", "puma560", "0", "0", "0", "0", "0", "0"])
    assert loaded == {"casadi"}, err


def test_interrupt_while_starting_is_one_line():
    """A KeyboardInterrupt raised while the command modules are imported (Ctrl-C at start-up)."""
    code = ("import sys\n"
            "class Stop:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name == 'studies.cli.main':\n            raise KeyboardInterrupt\n"
            "sys.meta_path.insert(0, Stop())\n"
            "from studies.cli import main\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert p.returncode == 130
    assert p.stderr == "rmt: interrupted\n" and p.stdout == ""


def test_interrupt_while_running_is_one_line(capsys, monkeypatch):
    import kin

    def interrupted(name):
        raise KeyboardInterrupt
    monkeypatch.setattr(kin, "load_robot", interrupted, raising=False)
    assert main(["fk", "puma560", "0", "0", "0", "0", "0", "0"]) == 130
    out, err = capsys.readouterr()
    assert err == "rmt: interrupted\n" and out == ""


def test_follow_modes_are_the_followers():
    from planning.follow import MODES as FOLLOWER_MODES
    assert tuple(MODES) == tuple(FOLLOWER_MODES)


@pytest.mark.parametrize("argv", [["fk"], ["nonsense"], ["fk", "puma560", "x", "0", "0", "0", "0", "0"]])
def test_usage_errors_are_one_line(capsys, argv):
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("rmt: error:")


def test_a_percent_sign_in_a_command_help_does_not_break_help(capsys, monkeypatch):
    """`rmt --help` %-formats every command's help: "reach %" used to raise ValueError (a traceback)."""
    import types
    cm = sys.modules["studies.cli.main"]           # (the package's `main` attribute is the function)

    def add_commands(add):
        add("percent", lambda args, load_robot: 0, "coverage: reach %, covered %")
    monkeypatch.setattr(cm, "GROUPS", cm.GROUPS + (types.SimpleNamespace(add_commands=add_commands),))
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "coverage: reach %, covered %" in out
    assert main(["percent", "--help"]) == 0
    assert "coverage: reach %, covered %" in capsys.readouterr().out
