"""One-line CLI messages a new user met: no doubled "rmt: " prefix, the --tcp values printed plainly."""
from __future__ import annotations

from studies.cli import main


def _err(capsys, *argv) -> tuple[int, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, err.strip()


def test_unrecognized_arguments_name_the_command_once(capsys):
    code, err = _err(capsys, "fk", "puma560", "0", "0", "0", "0", "0", "0", "--bogus", "-93.49")
    assert code == 2
    assert err == "rmt: error: rmt fk: unrecognized arguments: --bogus -93.49"
    code, err = _err(capsys, "--bogus")
    assert code == 2 and err.startswith("rmt: error: ") and "rmt: error: rmt:" not in err
