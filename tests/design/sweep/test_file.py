"""Sweep files: a valid file's values (SI), and one-line errors naming the field for bad ones."""
import pytest

from design.sweep import SweepError, load_sweep, loads_sweep
from tests.design.sweep.helpers import write_sweep


def test_valid_file_in_si(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, counts=(4, 3)))
    assert [p.name for p in sw.parameters] == ["A1", "A2"]
    assert sw.parameters[0].low == pytest.approx(0.1) and sw.parameters[0].high == pytest.approx(0.4)
    assert (sw.sampling, sw.seeds, sw.samples, sw.architectures) == ("grid", 2, 300, ("",))


@pytest.mark.parametrize("body,field", [
    ('task = "task.toml"\n[parameters.A1]\nrange = [100, 400]\ncount = 3', "name"),
    ('name = "x"\ntask = "nope.toml"\n[parameters.A1]\nrange = [100, 400]\ncount = 3', "task"),
    ('name = "x"\ntask = "task.toml"\n[parameters.B9]\nrange = [100, 400]', "parameters.B9"),
    ('name = "x"\ntask = "task.toml"\n[parameters.A1]\nrange = [50, 400]\ncount = 3', "parameters.A1.range"),
    ('name = "x"\ntask = "task.toml"\n[parameters.A1]\nrange = [300, 200]\ncount = 3', "parameters.A1.range"),
    ('name = "x"\ntask = "task.toml"\n[parameters.A1]\nrange = [100, 400]', "parameters.A1.count"),
    ('name = "x"\ntask = "task.toml"\n[sampling]\nmethod = "sobol"\ncount = 10\n[parameters.A1]\nrange = [100, 400]',
     "sampling.count"),
    ('name = "x"\ntask = "task.toml"\n[sampling]\nmethod = "random"\n[parameters.A1]\nrange = [100, 400]',
     "sampling.method"),
    ('name = "x"\ntask = "task.toml"\nmetrics = ["speed"]\n[parameters.A1]\nvalues = [200]', "metrics[0]"),
    ('name = "x"\ntask = "task.toml"\narchitecture = ["RR"]\n[parameters.A1]\nvalues = [200]', "architecture[0]"),
    ('name = "x"\ntask = "task.toml"\n[evaluation]\nseeds = 0\n[parameters.A1]\nvalues = [200]', "evaluation.seeds"),
    ('name = "x"\ntask = "task.toml"\n[parameters.A1]\nvalues = [200, 900]', "parameters.A1.values[1]"),
    ('name = "x"\ntask = "task.toml"\nspeed = 3\n[parameters.A1]\nvalues = [200]', "speed"),
])
def test_bad_fields_are_named(tmp_path, body, field):
    write_sweep(tmp_path)                                   # writes task.toml
    with pytest.raises(SweepError) as e:
        loads_sweep(body, "s.toml", tmp_path)
    msg = str(e.value)
    assert msg.startswith(f"s.toml: {field}:") and "\n" not in msg
