"""``rmt study``: the list of bundled studies, bad names and files refused in one line (exit 2)."""
from __future__ import annotations

from studies import bundled
from studies.cli import main


def test_list_shows_every_bundled_study(capsys):
    assert main(["study", "--list"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in out] == list(bundled.STUDIES)
    assert out[0].endswith("(default)") and out[0].startswith("fanuc_singularities")
    for line, name in zip(out, bundled.STUDIES):
        assert bundled.load(name).TITLE in line


def test_every_bundled_study_is_a_complete_module():
    for name in bundled.STUDIES:
        mod = bundled.load(name)
        assert mod.NAME == name and mod.TITLE and callable(mod.run)
        assert mod.__doc__ and len(mod.__doc__.split()) >= 20       # the report's introduction


def test_unknown_study_is_refused(capsys, tmp_path):
    assert main(["study", "no_such_study", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "fanuc_singularities" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_missing_study_file_is_refused(capsys, tmp_path):
    assert main(["study", str(tmp_path / "nope.toml"), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nope.toml" in err
