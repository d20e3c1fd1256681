import tempfile, collections, sys
from pathlib import Path
from hypothesis import given, settings, HealthCheck
import tests.fuzz.test_arguments as T
from tests.fuzz.contract import run_contract
stats = collections.Counter()
@settings(max_examples=int(sys.argv[1]), deadline=None, derandomize=False, database=None, suppress_health_check=list(HealthCheck))
@given(T.argv())
def t(case):
    args, outputs = case
    with tempfile.TemporaryDirectory() as d:
        cwd = Path(d)
        (cwd / "p.csv").write_text(T.PATH_CSV)
        (cwd / "r.toml").write_text("name = 'x'\n")
        code, out, err = run_contract(args, cwd, outputs)
        stats[(args[0] if args else "", code)] += 1
t()
print(sorted(stats.items()))
