"""Which modules, in which order, serve a family of three parts — and is one machine for all of them
cheaper than a base machine reconfigured for each part?

The modules are the bundled catalogue `dynamixel_y` (`rmt modules dynamixel_y`): ROBOTIS DYNAMIXEL-Y
rotary modules of two housing sizes and two gear ratios, tube cranks, elbow brackets and a reducer
plate, a steel base plate and a pedestal, a gripper and a spindle — masses, torques and housings from
the maker's data sheets, costs estimated by a stated rule (the catalogue's `source`).  The parts
(`studies/tasks/parts/`) are a panel with a seam of glue dots, a tray of parts to pick far out on the
table, and an upright fixture plate to probe near the base: positions to 0.1 mm, the tools' own
compliance taking the orientation.

For each part alone, `design.compose.compose` searches the assemblies of the space below in
non-decreasing cost: proven bounds (the tool point's reach from the first axis, the freedom of
parallel axes, whether every joint holds the chain at rest) empty most of it before any reach
study, kinematic twins (modules of the same housing) share one, and the first assembly whose reach
study reaches every target is the cheapest.  `design.compose.reconfigure` then chooses a *base*
assembly and one assembly per part — among each part's cheapest, each judged for every other part —
to minimise the modules one must own (each module type's largest count in any configuration) plus a
cost per swap, against the cheapest single machine for all three.  Every chosen assembly is verified
by a denser reach study (twice the starts among four times the samples), its reach map drawn, and
its robot file written; a 3-D view shows each configuration at a reached target.

Run it with ``rmt study module_reconfiguration`` (``--quick`` for a smaller space) or ``python
studies/bundled/module_reconfiguration.py --out DIR``.  Copy it to try another catalogue
(:data:`CATALOGUE`), other parts (:data:`PARTS`), another swap cost or a larger space
(:func:`space_of`); `rmt compose` runs the same search from the command line.
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

import studies
from design.compose import ComposeSettings, ComposeSpace, compose, load_part
from design.compose.reconfigure import reconfigure
from design.compose.verdict import assembled, verify
from design.reach import ReachSettings
from kin import Robot, dumps_robot
from kin.modules import load_catalogue
from planning.collision import collision_world
from studies.plots.reach import plot_reach
from studies.report.cell_view import cell_view
from studies.study import Study, main

NAME = "module_reconfiguration"
TITLE = "A family of three parts from one module catalogue: one machine, or a base machine and swaps"

CATALOGUE = "dynamixel_y"
PARTS = [Path(studies.__file__).parent / "tasks" / "parts" / f"{n}.toml"
         for n in ("panel_dispense", "tray_pick", "fixture_probe")]
#: the cost of one swap (EUR, an estimate: about two hours of a fitter's time to unbolt, bolt and re-home)
SWAP_COST = 150.0


def space_of(cat, parts, quick: bool) -> ComposeSpace:
    """The assemblies searched: on the steel base plate, with the gripper (its mass stands for every
    part's tool), 3 to 4 joint modules (4 only with --quick), at most one link after each."""
    return ComposeSpace.for_parts(cat, parts, joints=(4, 4) if quick else (3, 4), bases=["BASE"], tools=["GRIP"],
                                  links_per_joint=1)


def run(s: Study) -> None:
    with tempfile.TemporaryDirectory(prefix="rmt-modules-") as scratch:
        study(s, Path(scratch))


def study(s: Study, scratch: Path) -> None:
    cat = load_catalogue(CATALOGUE)
    parts = [load_part(p) for p in PARTS]
    quick = s.quick
    k = s.input("cheapest assemblies kept per part (the reconfiguration's candidates)", 1 if quick else 3)
    swap = s.input(f"cost of one swap ({cat.currency})", SWAP_COST)
    starts = s.input("reach study: IK starts per target", 4 if quick else 8)
    samples = s.input("reach study: Halton samples the starts are chosen from", 1024 if quick else 4096)
    settings = ComposeSettings(reach=ReachSettings(starts=starts, samples=samples))
    single = s.input("search the cheapest single machine for all parts (s of budget; 0: among the candidates only)",
                     0 if quick else 180)
    space = space_of(cat, parts, quick)
    mm = 1e3

    with s.section("The catalogue and the parts"):
        s.text(f"**{cat.title}** — {len(cat.modules)} modules: {len(cat.of_kind('joint'))} joint modules, "
               f"{len(cat.of_kind('link'))} links, {len(cat.of_kind('base'))} bases, {len(cat.of_kind('tool'))} tools "
               f"(`rmt modules {CATALOGUE}` lists them; docs/modules.md gives every number's source).")
        rows = []
        for m in cat.modules.values():
            rows.append([m.kind, m.name, m.cost, m.proximal.mass + m.distal.mass,
                         "" if m.max_torque is None else m.max_torque, m.title])
        s.table(["kind", "module", f"cost ({cat.currency})", "mass (kg)", "max torque (N·m)", "what"], rows,
                caption="The catalogue's modules (costs are estimates, stated as such in its source).")
        s.table(["part", "targets", "x (mm)", "y (mm)", "z (mm)", "what"],
                [[p.name, len(p.targets), *(f"{mm * lo:.0f} … {mm * hi:.0f}" for lo, hi in
                                             zip(p.targets.positions.min(0), p.targets.positions.max(0))), p.title]
                 for p in parts], caption="The family: each part's targets (robot base frame).")
        s.text(f"The space searched: {space.describe()} — {space.size():,} assemblies once twists proven to give "
               "the same machine are merged.")

    found = {}
    with s.section("Each part alone"):
        rows = []
        for p in parts:
            s.say(f"composing for {p.name}")
            r = compose(cat, [p], space, settings, k=k, progress=s.say)
            found[p.name] = r
            best = r.found[0] if r.found else None
            c = r.counts
            rows.append([p.name, best.assembly.text(cat) if best else "none found", best.cost if best else "—",
                         c["evaluated"], c["dof"] + c["reach_bound"] + c["holding"], "yes" if r.exhaustive else "no",
                         r.seconds])
        s.table(["part", "least-cost assembly", f"cost ({cat.currency})", "reach studies", "proven empty",
                 "exhaustive", "time (s)"], rows,
                caption="The cheapest assembly of the space for each part alone: everything cheaper was judged "
                        "or proven unable to serve it (exhaustive: yes).")
        for p in parts:
            s.code("\n".join(found[p.name].lines()), f"rmt compose {CATALOGUE} {p.name} (the search's account)",
                   collapsed=True)

    with s.section("One machine, or a base machine and swaps"):
        cands = [[f.assembly for f in found[p.name].found] for p in parts]
        if any(not c for c in cands):
            s.finding("a part has no assembly in this space: no plan", ok=False)
            return
        plan = reconfigure(cat, parts, space, swap_cost=swap, k=k, settings=settings, candidates=cands,
                           progress=s.say, verify=False, single_search=single > 0, budget_s=single or None)
        s.code("\n".join(plan.lines()), "The plan (as `rmt compose --swap-cost` prints it)")
        s.file("plan.json", json.dumps(plan.to_json(), indent=1, allow_nan=False))
        if plan.base is None:
            s.finding("no plan: a part has no candidate", ok=False)
            return
        s.finding(f"Base machine {plan.base_text}, {plan.swaps} swap(s) in all: {plan.comparison()}.", ok=True)
        s.table(["part", "configuration", "swaps from the base"],
                [[n, t, "; ".join(ops) or "none (the base itself)"]
                 for n, t, ops in zip(plan.parts, plan.texts, plan.operations)],
                caption="Each part's configuration and the swaps that make it from the base machine.")
        s.table(["module", "count owned", f"unit cost ({cat.currency})"],
                [[n, c, cat.modules[n].cost] for n, c in plan.inventory.items()],
                caption="The modules to own: each type's largest count in any one configuration.")

    with s.section("Each configuration: verified, mapped, shown"):
        for p, a in zip(parts, plan.assemblies):
            st = verify(cat, a, p, settings.verify)
            s.text(f"**{p.name}** with `{a.text(cat)}`: the denser reach study ({settings.verify.starts} starts "
                   f"among {settings.verify.samples} samples) reaches {int(st.reached.sum())} of {len(st)} targets.")
            s.finding(f"{p.name}: {int(st.reached.sum())}/{len(st)} targets reached by the verification",
                      ok=bool(st.reached.all()))
            png = plot_reach(st, scratch / f"reach_{p.name}.png", length_scale=1e-3, length_unit="mm",
                             title=f"{p.name}: {a.text(cat)}")
            s.image(png, f"Reach map of {p.name}: each target's score (grey ×: missed).")
            chain = assembled(cat, a)
            s.file(f"{p.name}_robot.toml", dumps_robot(chain))
            robot = Robot(chain)
            q = np.asarray(st.q)[int(np.flatnonzero(st.reached)[0])] if st.reached.any() else np.zeros(robot.n)
            world = collision_world(robot)
            s.view3d(cell_view(world, q, title=f"{p.name}: {a.text(cat)}", closest=None,
                               points=[("targets", p.targets.positions, "#d62728")], shape=None),
                     f"view_{p.name}", f"{p.name}'s configuration at its first reached target, the targets in red.")


if __name__ == "__main__":
    import sys
    sys.exit(main(sys.modules[__name__]))
