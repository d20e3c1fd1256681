"""``rmt compose --swap-cost`` (the reconfiguration options): bad input refused with one line before
any work; a plan for two parts of the small test catalogue whose numbers add up from the catalogue's
costs and whose swaps turn the base into each part's assembly, its verdicts taken from the ``--store``
cache on a second run (slow: real reach studies)."""
from __future__ import annotations

import json
import re
from collections import Counter
from pathlib import Path

import pytest

from design.compose.edits import apply_script, edit_script
from kin import load_robot
from kin.modules import Assembly, load_catalogue
from studies.cli import main

HERE = Path(__file__).resolve().parent
CATALOGUE = str(HERE.parents[1] / "kin" / "modules" / "small_catalogue.toml")
PARTS = [str(HERE / "reconfigure_parts" / f"{n}.toml") for n in ("near", "far")]
SPACE = ["--joints", "2-3", "--tool", "T", "--starts", "4", "--samples", "1024"]


def run(capsys, *argv):
    code = main(["compose", CATALOGUE, *PARTS, *SPACE, *argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("argv, msg", [
    (["--swap-cost", "-5"], r"--swap-cost: -5 is outside the allowed range \[0, 1e\+12\]"),
    (["--swap-cost", "nan"], "--swap-cost: nan is outside the allowed range"),
    (["--swap-cost", "100", "--candidates", "0"], r"--candidates: 0 is outside the allowed range \[1, 50\]"),
    (["--candidates", "3"], "--candidates needs --swap-cost"),
    (["--swap-cost", "100", "--dask", "scheduler:8786"], "--dask 'scheduler:8786' must be local or a scheduler "
                                                          "address like tcp://HOST:PORT"),
])
def test_bad_options_are_refused_with_one_line(capsys, argv, msg):
    code, out, err = run(capsys, *argv)
    assert code == 2 and re.search(msg, err) and len(err.strip().splitlines()) == 1 and out == ""


def test_a_store_that_is_not_a_verdict_cache_is_left_alone(capsys, tmp_path):
    notes = tmp_path / "notes.db"
    notes.write_text("my notes\n")
    code, out, err = run(capsys, "--swap-cost", "100", "--store", str(notes))
    assert code == 2 and "notes.db: not an SQLite database; refusing to use or overwrite it (choose another --store)" \
        in err and len(err.strip().splitlines()) == 1
    assert notes.read_text() == "my notes\n"


@pytest.mark.slow
def test_a_plan_adds_up_and_a_second_run_takes_its_verdicts_from_the_store(capsys, tmp_path):
    db, out_dir = tmp_path / "verdicts.sqlite", tmp_path / "plan"
    code, out, err = run(capsys, "--swap-cost", "100", "--candidates", "2", "--store", str(db), "--json",
                         "--out", str(out_dir))
    assert code == 0, err
    plan = json.loads(out)
    cat = load_catalogue(CATALOGUE)
    base = Assembly.parse(plan["base"], cat)
    configs = [Assembly.parse(c["assembly"], cat) for c in plan["configurations"]]
    # the modules owned: each type's largest count over the configurations, priced from the catalogue
    owned = Counter()
    for a in (base, *configs):
        for n, c in Counter(a.modules).items():
            owned[n] = max(owned[n], c)
    assert plan["inventory"] == dict(owned)
    assert plan["inventory_cost"] == pytest.approx(sum(cat.modules[n].cost * c for n, c in owned.items()), abs=1e-9)
    swaps = sum(c["swaps"] for c in plan["configurations"])
    assert plan["swaps"] == swaps and plan["total"] == pytest.approx(plan["inventory_cost"] + 100 * swaps, abs=1e-9)
    for a, c in zip(configs, plan["configurations"]):
        script = edit_script(base, a, cat)
        assert apply_script(base, script) == a and len(script) == c["swaps"] == len(c["operations"])
    assert all(v["reached"] == v["targets"] for v in plan["verification"])
    # the single assembly for both parts: none at the plan's total or below, or one no dearer than it
    assert plan["single_scope"] in ("space", "below")
    if plan["single"] is not None:
        assert plan["single"]["cost"] >= plan["total"] - 1e-9
    robots = {k: v for k, v in plan["files"].items() if k.startswith("robot")}
    assert set(robots) == {"robot base", "robot near", "robot far"}
    assert load_robot(robots["robot far"]).n == len(configs[1].joints(cat))
    # again, in text: every verdict from the cache, the same plan
    code, text, err = run(capsys, "--swap-cost", "100", "--candidates", "2", "--store", str(db))
    assert code == 0, err
    taken = re.search(r"verdict cache .*verdicts.sqlite: (\d+) taken, 0 judged and added", text)
    assert taken and int(taken.group(1)) > 0, text
    assert f"base assembly: {plan['base']}" in text and "total: " in text
