"""Issue 32: hostile module catalogues and assemblies are refused with ONE line naming the file and the
field (kin.modules.CatalogueError; ``rmt modules`` and ``rmt assemble`` exit 2 with it on stderr):
unknown connectors, negative masses, a module that connects to nothing, a 10⁶-module file (the count
limit; a file over 10 MB by its size before it is parsed), a cycle of ``like`` rules, unknown fields,
NaN and infinity, bad twists, duplicate names; nothing is evaluated.  Assemblies: a twist the
connectors do not allow, incompatible connectors, more than 8 joints, a tool in the middle."""
from __future__ import annotations

import os

import pytest

from kin.modules import AssemblyError, CatalogueError, load_catalogue, loads_catalogue
from kin.modules.catalogue import MAX_CATALOGUE_BYTES, MAX_MODULES
from studies.cli import main
from tests.kin.modules.plain import FIXTURE

BASE = FIXTURE.read_text()

# (id, text replaced, replacement, field named, words of the message)
CASES = [
    ("unknown connector", 'input = "F63"\noutput = "F63"\ntype = "revolute"',
     'input = "F99"\noutput = "F63"\ntype = "revolute"', "modules[5] (R63).input", "unknown connector type 'F99'"),
    ("negative mass", "mass = 1.2", "mass = -1", "modules[6] (L200).inertial.mass", "≥ 0"),
    ("connects to nothing", "[connectors.F63]", "[connectors.G]\ntwists = [0]\n[connectors.F63]", None, None),
    ("like cycle", '[connectors.F80_tool]\nlike = "F80"',
     '[connectors.F80_tool]\nlike = "X"\n[connectors.X]\nlike = "Y"\n[connectors.Y]\nlike = "X"',
     "connectors.", "cycle"),
    ("unknown field", 'name = "L63"\n', 'name = "L63"\ncolour = "red"\n', "modules[9]", "colour"),
    ("nan mass", "mass = 0.4", "mass = nan", "modules[8] (A80_63).inertial.mass", "finite"),
    ("inf cost", "cost = 110", "cost = inf", "modules[9] (L63).cost", "finite"),
    ("inf length", "length = 150", "length = -inf", "modules[9] (L63).length", "finite"),
    ("nan twist", "twists = [0, 180]", "twists = [0, nan]", "connectors.F63.twists[1]", "finite"),
    ("text twist", "twists = [0, 180]", 'twists = [0, "half"]', "connectors.F63.twists[1]", "number"),
    ("repeated twist", "twists = [0, 180]", "twists = [0, 180, 540]", "connectors.F63.twists[2]", "repeats"),
    ("empty twists", "twists = [0, 180]", "twists = []", "connectors.F63.twists", "non-empty"),
    ("duplicate name", 'name = "L63"', 'name = "L200"', "modules[9].name", "defined twice"),
    ("code as a cost", "cost = 110", "cost = \"__import__('os').system('touch PWNED')\"", "modules[9] (L63).cost",
     "number"),
    ("code as a name", 'name = "L63"', "name = \"__import__('os').system('touch PWNED')\"", "modules[9].name",
     "must match"),
    ("bad kind", 'kind = "tool"\ntitle = "a 20 kg', 'kind = "spindle"\ntitle = "a 20 kg', "modules[12].kind",
     "spindle"),
    ("joint without torque", "max_torque = 8\n", "", "modules[5] (R63).max_torque", "missing"),
    ("bad units", 'length_unit = "mm"', 'length_unit = "furlong"', "length_unit", "furlong"),
    ("not toml", "[[modules]]", "[[modules]", None, "not valid TOML"),
]


def _connects_to_nothing():
    # a joint whose input type G no chain of modules from a base ever offers
    return BASE.replace("[connectors.F63]", "[connectors.G]\ntwists = [0]\n[connectors.F63]").replace(
        'name = "R63"\nkind = "joint"\ntitle = "small rotary module, weak"\ncost = 2100\ninput = "F63"',
        'name = "R63"\nkind = "joint"\ntitle = "small rotary module, weak"\ncost = 2100\ninput = "G"')


def _text(case_id, old, new):
    if case_id == "connects to nothing":
        return _connects_to_nothing()
    assert old in BASE, old
    return BASE.replace(old, new, 1)


def _check_one_line(msg: str, path: str, field: str | None, words: str | None):
    assert "\n" not in msg.strip(), msg
    assert msg.startswith(f"{path}: "), msg
    if field:
        assert f": {field}" in msg, msg
    if words:
        assert words in msg, msg


@pytest.mark.parametrize("case_id, old, new, field, words", CASES, ids=[c[0] for c in CASES])
def test_hostile_catalogue_is_one_line_naming_file_and_field(case_id, old, new, field, words, tmp_path, capsys,
                                                             monkeypatch):
    monkeypatch.chdir(tmp_path)
    if case_id == "connects to nothing":
        field, words = "modules[5] (R63).input", "connects to nothing"
    path = tmp_path / "hostile.toml"
    path.write_text(_text(case_id, old, new))
    with pytest.raises(CatalogueError) as e:
        load_catalogue(path)
    _check_one_line(str(e.value), str(path), field, words)
    for argv in (["modules", str(path)], ["assemble", str(path), "--modules", "stand", "R80", "--out", "a.toml"]):
        assert main(argv) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1 and err.startswith(f"rmt: error: {path}: "), err
    assert os.listdir(tmp_path) == ["hostile.toml"]              # nothing evaluated, nothing written


def test_the_fixture_itself_loads():
    cat = loads_catalogue(BASE, "fixture.toml")
    assert len(cat.modules) == 13 and cat.connectors["F80_tool"].root == "F80"


def test_a_million_modules_are_refused_by_the_count():
    text = "modules = [" + "{}," * 10**6 + "]\n" + BASE.split("[[modules]]", 1)[0]     # keys before tables
    with pytest.raises(CatalogueError) as e:
        loads_catalogue(text, "big.toml")
    assert str(e.value) == f"big.toml: modules: 1000000 modules; at most {MAX_MODULES}"


def test_a_file_over_10_mb_is_refused_by_its_size(tmp_path, capsys):
    path = tmp_path / "huge.toml"
    path.write_text("[[modules]]\n" * (MAX_CATALOGUE_BYTES // 12 + 1))
    assert path.stat().st_size > MAX_CATALOGUE_BYTES
    with pytest.raises(CatalogueError) as e:
        load_catalogue(path)
    _check_one_line(str(e.value), str(path), None, "MB")
    assert main(["modules", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err


def test_an_unknown_catalogue_name_lists_the_bundled(capsys):
    assert main(["modules", "no_such_catalogue"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown catalogue 'no_such_catalogue'" in err


# ---- assemblies -----------------------------------------------------------------------------------
ASSEMBLY_CASES = [
    ("twist not allowed", "stand A80_63 R63@90", "modules[2] 'R63': twist 90 deg", "allowed: 0, 180"),
    ("twist between allowed ones", "stand R80@45", "modules[1] 'R80': twist 45 deg", "allowed: 0, 90, 180, 270"),
    ("incompatible connectors", "stand R63", "modules[1] 'R63': its input 'F63' does not meet", "'F80' of 'stand'"),
    ("nine joints", "stand " + " ".join(["R80"] * 9), "9 joints", "at most 8"),
    ("tool in the middle", "stand R80 grip R80", "modules[2] 'grip' is a tool", "only the last"),
    ("base in the middle", "stand R80 stand", "modules[2] 'stand' is a base", "only the first"),
    ("no base", "R80 R80", "modules[0] 'R80' is a joint module", "starts at a base"),
    ("no joint", "stand L200 grip", "no joint", ""),
    ("unknown module", "stand R99", "no module 'R99'", "fixture_modules"),
    ("text twist", "stand R80@ninety", "modules[1] 'R80@ninety'", "finite number"),
    ("nan twist", "stand R80@nan", "modules[1] 'R80@nan'", "finite number"),
    ("inf twist", "stand R80@inf", "modules[1] 'R80@inf'", "finite number"),
]


@pytest.mark.parametrize("case_id, text, first, second", ASSEMBLY_CASES, ids=[c[0] for c in ASSEMBLY_CASES])
def test_bad_assembly_is_one_line(case_id, text, first, second, tmp_path, capsys):
    out = tmp_path / "arm.toml"
    assert main(["assemble", str(FIXTURE), "--modules", *text.split(), "--out", str(out)]) == 2
    o, err = capsys.readouterr()
    assert o == "" and err.count("\n") == 1 and err.startswith("rmt: error: "), err
    assert first in err and second in err, err
    assert not out.exists()
    from kin.modules import Assembly
    with pytest.raises(AssemblyError):
        Assembly.parse(text.split(), load_catalogue(FIXTURE))
