"""Using built windows imports no symbolic machinery: a fresh interpreter imports the planning
packages, loads a windows file (an interval window and a |g| ≤ ε window, written here by hand),
checks membership, certifies a path, separates start and goal by free cells and asks the OMPL
validity checker — and sympy, scipy.stats, scipy.ndimage and the singular analysis stay unloaded."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap

SHOULDER = "0.74*sin(q2 + q3) + 0.77*cos(q2) + 0.1*cos(q2 + q3) + 0.15"     # FANUC M-16iB/20 shoulder factor
HEAVY = ("sympy", "scipy.stats", "scipy.ndimage", "kin.singular.analysis", "kin.singular.numeric",
         "kin.singular.exact")

SCRIPT = textwrap.dedent('''
    import json, math, sys
    import numpy as np
    import planning.ompl, planning.certify, planning.windows
    from planning.certify import certify_path
    from planning.certify.cells import FreeCells
    from planning.windows import WindowSet

    ws = WindowSet.load(sys.argv[1])
    g = lambda q2, q3: 0.74 * math.sin(q2 + q3) + 0.77 * math.cos(q2) + 0.1 * math.cos(q2 + q3) + 0.15
    a, b = -1.0, 1.0                              # a zero of g at q2 = 2 (g(2, -1) > 0 > g(2, 1))
    for _ in range(80):
        m = 0.5 * (a + b)
        a, b = (m, b) if (g(2.0, m) > 0) == (g(2.0, a) > 0) else (a, m)
    z = 0.5 * (a + b)
    Q = np.array([[0.1, 0.2, 0.3, 0.0, 0.5, 0.0],      # clear
                  [0.1, 0.2, 0.3, 0.0, 0.01, 0.0],     # wrist
                  [0.1, 2.0, z, 0.0, 0.5, 0.0]])       # shoulder
    out = {"membership": ws.membership(Q).tolist(), "which": ws.which(Q).tolist()}
    clear = np.array([[0.1, 0.2, 0.3, 0.0, 0.5, 0.0], [0.2, 0.3, 0.2, 0.1, 0.6, 0.1], [0.3, 0.4, 0.1, 0.2, 0.7, 0.2]])
    p = certify_path(ws, clear)
    out["clear"] = [p.proven, p.methods, p.pieces]
    cross = np.array([[0.1, 2.0, z - 0.3, 0.0, 0.5, 0.0], [0.1, 2.0, z + 0.3, 0.0, 0.5, 0.0],
                      [0.1, 2.0, z + 0.4, 0.0, 0.5, 0.0]])
    p = certify_path(ws, cross)
    out["cross"] = [p.proven, None if p.violation is None else [p.violation.segment, p.violation.window]]
    lower = np.array([-2.97, -1.57, -2.97, -3.49, -2.44, -7.85])
    upper = -lower
    cells = FreeCells(lower, upper, ws)
    sep = cells.separation(clear[0], np.array([0.1, 0.2, 0.3, 0.0, -0.5, 0.0]))
    out["separation"] = None if sep is None else [sep.kind, list(sep.joints)]
    cells.separation(clear[0], clear[0])       # the slabs first: a query on one side of them builds the grid
    out["grids"] = [list(k) for k, v in cells._grids.items() if v is not None]

    import kin
    from planning.ompl.validity import JointSpaceChecker
    checker = JointSpaceChecker(kin.load_robot("fanuc_m16ib20"), ws)
    out["state_valid"] = [checker.state_valid([float(x) for x in q]) for q in Q]
    out["motion_valid"] = [checker.motion_valid(clear[0], clear[1]), checker.motion_valid(cross[0], cross[1])]
    out["loaded"] = [m for m in sys.argv[2:] if m in sys.modules]
    print(json.dumps(out))
''')


def test_using_loaded_windows_imports_no_symbolic_machinery(tmp_path):
    doc = {"robot": "fanuc_m16ib20", "n": 6, "units": "SI (rad, m)", "windows": [
        {"name": "wrist: sin(q5)", "kind": "wrist", "expr": "sin(q5)", "joints": [5], "width": 0.05,
         "method": "margin", "detail": {}, "intervals": [[-0.05, 0.05]]},
        {"name": "shoulder", "kind": "shoulder", "expr": SHOULDER, "joints": [2, 3], "width": 0.05,
         "method": "margin", "detail": {}, "epsilon": 0.05}]}
    path = tmp_path / "windows.json"
    path.write_text(json.dumps(doc))
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(path), *HEAVY], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["membership"] == [[False, False], [True, False], [False, True]]
    assert out["which"] == [-1, 0, 1]
    proven, methods, pieces = out["clear"]
    assert proven and methods == {"wrist: sin(q5)": "exact", "shoulder": "interval"} and pieces > 0
    assert out["cross"] == [False, [0, "shoulder"]]
    assert out["separation"] == ["slab", [5]]
    assert out["grids"] == [[1, 2]]                  # the shoulder's (q2, q3) grid was built and labelled
    assert out["state_valid"] == [True, False, False]
    assert out["motion_valid"] == [True, False]
    assert out["loaded"] == [], f"using built windows imported {out['loaded']}"
