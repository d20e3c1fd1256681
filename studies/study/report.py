"""Plain-text report of a study's results (what ``rmt study`` prints)."""
from __future__ import annotations

from pathlib import Path


def study_report(results: dict, path: Path) -> str:
    rb = results["robot"]
    u = rb["units"]
    out = [f"{results.get('title') or results['study']}  [{rb['name']}: {rb['title']}; backend {results['backend']}]",
           f"{rb['convention']} DH ({u['length']}, {u['angle']}):",
           f"{'i':>2} {'a':>9} {'alpha':>9} {'d':>9} {'theta':>9}   limits"]
    for r in rb["dh"]:
        out.append(f"{r['joint']:>2} " + " ".join(f"{r[f]:>9.4g}" if not isinstance(r[f], str) else f"{r[f]:>9}"
                                                 for f in ("a", "alpha", "d", "theta"))
                   + f"   [{r['limits'][0]:.4g}, {r['limits'][1]:.4g}]")
    out += ["", f"{'configuration':<48} {'x':>8} {'y':>8} {'z':>8} {'manip':>10} {'sigma_min':>10} {'cond':>10}"]
    for r in results["configurations"]:
        cond = "inf" if r["condition"] is None else f"{r['condition']:.4g}"
        flag = "" if r["within_limits"] else "  (outside limits)"
        out.append(f"{r['label'][:48]:<48} " + " ".join(f"{x:>8.4f}" for x in r["position"])
                   + f" {r['manipulability']:>10.4g} {r['sigma_min']:>10.4g} {cond:>10}{flag}")
    s = results.get("singularities")
    if s:
        out += ["", f"singular set ({s['method']}; {s['seconds']:.2f} s):"]
        for f in s["factors"]:
            out.append(f"  [{f['kind']}] {f['expr']} = 0   — {f['meaning']}")
    w = results.get("windows")
    if w:
        out += ["", f"windows (cover {100 * w['share_of_joint_space']:.1f} % of the joint space):"]
        for win in w["windows"]:
            if "intervals" in win:
                ivs = " ∪ ".join(f"[{lo:.4g}, {hi:.4g}]" for lo, hi in win["intervals"])
                out.append(f"  {win['name']}: q{win['joints'][0]} ∈ {ivs} rad")
            elif win.get("epsilon") is not None:
                out.append(f"  {win['name']}: |g| ≤ {win['epsilon']:.4g}")
            else:                      # a point-set window of a numeric component
                out.append(f"  {win['name']}: within {win['width']:.4g} of its sampled points")
    ws = results.get("workspace")
    if ws:
        vol = f"volume ≈ {ws['volume']:.4g} m³ (voxel {1000 * ws['voxel']['size']:.3g} mm)" if ws["area"] is None \
            else f"area ≈ {ws['area']:.4g} m²"
        out += ["", f"workspace: {ws['counts']['samples']} samples, {vol}, functional "
                    f"{ws['functional_volume'] if ws['area'] is None else ws['functional_area']:.4g}; "
                    f"{100 * ws['counts']['near_singular_fraction']:.1f} % near-singular; reach {ws['reach']:.4g} m"]
    p = results.get("plan")
    if p:
        if p["success"]:
            out += ["", f"plan ({p['planner']}, {p['time_s']:.3f} s): {len(p['path'])} waypoints, joint-space length "
                        f"{p['length']:.4g} vs straight line {p['straight_line_length']:.4g}"
                        f"{' (blocked by a window)' if not p['straight_line_valid'] else ''}; min σ_min "
                        f"{p['min_sigma']:.3g}; dense check passed; windows "
                        f"{'proven clear along every segment' if p.get('proven') else 'sampled'}; "
                        "waypoints in plan.csv"]
        else:
            out += ["", f"plan: no path found ({p['status']})"]
    out += ["", f"report: {Path(path).resolve()}"]
    return "\n".join(out)
