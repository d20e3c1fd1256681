"""The least-cost assembly for a family of parts (:func:`compose`), and the k cheapest for one part
(:func:`cheapest`).

The space's assemblies come in non-decreasing cost order (ties: fewer joints, then the assembly's
text; :meth:`design.compose.space.ComposeSpace.ordered`).  A partial assembly whose every completion
provably misses a target (the reach bound with the most its completions can add) is dropped whole;
each complete one passes the dof and reach bounds and the holding check (:mod:`design.compose.bounds`)
before it is judged — in batches, through ``judge_many`` (serial in-process by default; a cached or
distributed one may be supplied), part by part, the next part only for the assemblies the earlier
ones left feasible.  The first feasible assembly in that order is the answer: every assembly before
it was judged infeasible or proven empty, so it has the least cost — **exhaustive**.

**Under a budget** (``budget_s`` seconds, ``max_judged`` verdicts) the search is exhaustive for the
first half; if no answer has come by then it turns into a stated heuristic for the second half: it
keeps to the cost order but judges only every s-th assembly that passes the bounds, s doubling after
every batch, so that costlier assemblies are reached; the answer is then the cheapest feasible one
*judged*, and the result says how many assemblies of at most its cost were not judged.  Either way
the answer is verified (:func:`design.compose.verdict.verify`: the reach study with another, denser
start set).
"""
from __future__ import annotations

import time
from typing import Callable, Sequence

from design.compose.bounds import PartGeometry, module_extent, partial_reach_bound, screen, sketch
from design.compose.result import COUNT_KEYS, ComposeResult, Found, Verification
from design.compose.space import ComposeSpace, Partial, Pruned
from design.compose.verdict import ComposeSettings, Verdict, held, judge, verify
from design.task.model import TaskError
from kin.modules import Assembly, AssemblyError, Catalogue

__all__ = ["compose", "cheapest", "serial_judge"]


def serial_judge(catalogue: Catalogue, settings: ComposeSettings) -> Callable[[list], list[Verdict]]:
    """The default ``judge_many``: every (assembly, part) judged here, one after the other."""
    return lambda items: [judge(catalogue, a, p, settings) for a, p in items]


def _check(catalogue: Catalogue, parts: Sequence, space: ComposeSpace) -> list:
    from design.compose.parts import Part
    parts = list(parts)
    if not parts:
        raise TaskError("compose needs at least one part")
    for p in parts:
        if not isinstance(p, Part):
            raise TaskError(f"a part must be a design.compose.Part (load_part), got {type(p).__name__}")
    names = [p.name for p in parts]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise TaskError(f"two parts are named {dup!r}; every part needs its own name")
    if space.catalogue is not catalogue:
        raise TaskError("the space was built on another catalogue")
    if space.cycle_free and any(p.cycle is not None for p in parts):
        bad = next(p.name for p in parts if p.cycle is not None)
        raise TaskError(f"part {bad!r} has a motion cycle: a joint's twist shifts its travel in joint space, so the "
                        "space may not merge full-turn joints' twists (build it without cycle_free)")
    if space.roll_free and any(p.needs_roll for p in parts):
        bad = next(p.name for p in parts if p.needs_roll)
        raise TaskError(f"part {bad!r} asks for full poses: the tool's turn about its axis matters, so the space "
                        "may not merge the tool's twists (build it without roll_free)")
    return parts


def compose(catalogue: Catalogue, parts: Sequence, space: ComposeSpace, settings: ComposeSettings | None = None,
            budget_s: float | None = None, progress: Callable[[str], None] | None = None,
            judge_many: Callable[[list], list[Verdict]] | None = None, max_judged: int | None = None,
            k: int = 1, trace: Callable[[str, object], None] | None = None) -> ComposeResult:
    """The least-cost assembly of ``space`` that serves every part (module text); with ``k`` > 1 the
    k cheapest.  ``progress(line)`` gets one line per batch; ``trace(what, item)`` every step:
    ("pruned", :class:`Pruned`), ("bound", (Assembly, stage, reason)), ("skipped", Assembly),
    ("judged", (Assembly, {part: Verdict}))."""
    t0 = time.perf_counter()
    parts = _check(catalogue, parts, space)
    settings = settings or ComposeSettings()
    if budget_s is not None and not (budget_s > 0):
        raise TaskError(f"budget_s must be a positive number of seconds, got {budget_s!r}")
    if max_judged is not None and (isinstance(max_judged, bool) or not isinstance(max_judged, int) or max_judged < 1):
        raise TaskError(f"max_judged must be a positive integer, got {max_judged!r}")
    judge_many = judge_many or serial_judge(catalogue, settings)
    geoms = [PartGeometry.of(p) for p in parts]
    counts = dict.fromkeys(COUNT_KEYS, 0)
    counts["total"] = space.size()
    counts["equivalent"] = space.size_all() - counts["total"]
    raw, ok = space.sequences()
    counts["sequences"], counts["incompatible"] = raw, raw - ok
    examples: dict[str, str] = {}

    def prune(p: Partial):
        rem = space.max_remaining(p.state, module_extent)
        sk = sketch(catalogue, p.modules, p.twists)
        for g in geoms:
            why = partial_reach_bound(sk, g, rem)
            if why:
                return "reach_bound", f"part {g.name}: {why}"
        return None

    gen = space.ordered(prune)
    found: list[Found] = []
    phase, stride, seen = "exhaustive", 1, 0
    frontier = None
    last_cost = None
    batches, exhausted, cut, popped = 0, False, False, 0
    notes: list[str] = []

    def over(frac: float) -> bool:
        late = budget_s is not None and time.perf_counter() - t0 > frac * budget_s
        many = max_judged is not None and counts["evaluated"] >= max(1, int(frac * max_judged))
        return late or many

    while True:
        batch: list[tuple[Assembly, object]] = []
        while len(batch) < settings.batch:
            popped += 1
            if popped % 64 == 0 and budget_s is not None:       # a long fill stops at the budget too
                if phase == "skip" and over(1.0):
                    cut = True
                    break
                if phase == "exhaustive" and batch and over(0.5):
                    break
            item = next(gen, None)
            if item is None:
                exhausted = True
                break
            if isinstance(item, Pruned):
                if trace:
                    trace("pruned", item)
                counts[item.stage] += item.count
                examples.setdefault(item.stage, f"every completion of {item.partial.assembly().text(catalogue)} …: "
                                                f"{item.reason}")
                continue
            a, cost = item
            last_cost = cost
            hit = screen(catalogue, a, geoms)
            if hit:
                if trace:
                    trace("bound", (a, hit[0], hit[2]))
                counts[hit[0]] += 1
                examples.setdefault(hit[0], f"{a.text(catalogue)}: part {hit[1]}: {hit[2]}")
                continue
            if phase == "skip":
                seen += 1
                if seen % stride:
                    if trace:
                        trace("skipped", a)
                    counts["not_judged"] += 1
                    continue
            try:
                why = held(catalogue, a)[1]
            except AssemblyError as e:          # a frame the DH extraction refuses: judged as such below
                why = None
                if len(notes) < 5:
                    notes.append(f"{a.text(catalogue)}: not assembled: {e}")
            if why:
                if trace:
                    trace("bound", (a, "holding", why))
                counts["holding"] += 1
                examples.setdefault("holding", f"{a.text(catalogue)}: {why}")
                continue
            batch.append((a, cost))
        if batch:
            batches += 1
            verdicts: list[dict[str, Verdict]] = [{} for _ in batch]
            alive = list(range(len(batch)))
            for part in parts:
                if not alive:
                    break
                got = judge_many([(batch[i][0], part) for i in alive])
                if len(got) != len(alive):
                    raise RuntimeError(f"judge_many returned {len(got)} verdicts for {len(alive)} assemblies")
                for i, v in zip(alive, got):
                    verdicts[i][part.name] = v
                alive = [i for i, v in zip(alive, got) if v.feasible]
            counts["evaluated"] += len(batch)
            for i, (a, cost) in enumerate(batch):
                if trace:
                    trace("judged", (a, verdicts[i]))
                if i not in alive:
                    counts["infeasible"] += 1
                elif len(found) < k:
                    found.append(Found(a, a.text(catalogue), float(cost), len(a.joints(catalogue)), verdicts[i]))
            if progress:
                lo, hi = float(batch[0][1]), float(batch[-1][1])
                pruned = counts["dof"] + counts["reach_bound"] + counts["holding"]
                progress(f"compose: batch {batches} ({phase}{'' if stride == 1 else f': 1 in {stride}'}): "
                         f"{len(batch)} judged at cost {lo:g}–{hi:g}, {len(alive)} feasible; so far judged "
                         f"{counts['evaluated']}, proven empty {pruned}; {time.perf_counter() - t0:.1f} s")
        if len(found) >= k or exhausted or cut:
            break
        if phase == "exhaustive" and over(0.5):
            phase, stride, frontier = "skip", 2, float(last_cost) if last_cost is not None else None
            at = "" if frontier is None else f" at cost {frontier:g}"
            notes.append(f"the budget's first half ran out{at}: every cheaper assembly was judged or proven empty; "
                         "then every s-th assembly passing the bounds was judged, s doubling per batch")
        elif phase == "skip":
            if over(1.0):
                cut = True
                break
            stride *= 2
    accounted = sum(counts[key] for key in ("dof", "reach_bound", "holding", "evaluated", "not_judged"))
    if found:
        counts["not_cheaper"] = counts["total"] - accounted
    elif cut:
        counts["not_judged"] += counts["total"] - accounted
    exhaustive = counts["not_judged"] == 0
    if exhaustive:
        frontier = found[0].cost if found else None
    verification = []
    if found and settings.verify is not None:
        for part in parts:
            st = verify(catalogue, found[0].assembly, part, settings.verify)
            reasons = st.reason_counts()
            verification.append(Verification(part.name, int(st.reached.sum()), len(st), settings.verify.starts,
                                             settings.verify.samples, settings.verify.spins, reasons))
    s = settings.reach
    notes.append(f"a reached target is a witness (a configuration that passes); an unreached one is the reach "
                 f"study's verdict (IK from {s.starts} starts among {s.samples} samples), not a proof")
    if counts["equivalent"]:
        notes.append("twist variants proven to be the same machine were left out: an axisymmetric link's or tool's "
                     "turn handed on to the next module (or the tool's own axis), a full-turn coaxial joint's taken "
                     "by its joint value (docs/modules.md)")
    return ComposeResult(catalogue=catalogue.name, currency=catalogue.currency, parts=[p.name for p in parts],
                         space=space.describe(), found=found, counts=counts, exhaustive=exhaustive, frontier=frontier,
                         examples=examples, verification=verification, notes=notes,
                         seconds=time.perf_counter() - t0, batches=batches)


def cheapest(catalogue: Catalogue, part, space: ComposeSpace, k: int, settings: ComposeSettings | None = None,
             budget_s: float | None = None, progress: Callable[[str], None] | None = None,
             judge_many: Callable[[list], list[Verdict]] | None = None,
             max_judged: int | None = None) -> ComposeResult:
    """The ``k`` cheapest assemblies of ``space`` feasible for one part, in cost order (``found``)."""
    if isinstance(k, bool) or not isinstance(k, int) or k < 1:
        raise TaskError(f"k must be a positive integer, got {k!r}")
    return compose(catalogue, [part], space, settings, budget_s, progress, judge_many, max_judged, k)
