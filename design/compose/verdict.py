"""Whether one assembly serves one part (:func:`judge` → :class:`Verdict`), cheapest test first:

1. ``incompatible`` — the assembly is not one (connectors that do not meet, a twist they do not allow);
2. ``dof``, ``reach_bound`` — the proven bounds of :mod:`design.compose.bounds`;
3. ``holding`` — the assembled robot provably cannot hold itself at rest (:func:`kin.modules.holding`);
4. ``reach`` — the reach study (:class:`design.reach.ReachProblem` at the part's placement, with its
   cell, clearance, dexterity and singular windows) must reach every target.  A reached target is a
   witness — a configuration within the limits, clear of the cell, outside the windows, dexterous
   enough; an unreached one is the study's verdict (its IK from fixed starts found none);
5. ``cycle`` — with a part cycle: timed on the assembled robot with the modules' own masses (and the
   part's payload at the tool), the cycle time within ``max_cycle_time`` and every peak torque within
   the joint's limit (:func:`design.cycle.evaluate_cycle`, torque ratio ≤ 1);
6. ``ok``.

:func:`verify` re-runs the reach study of an answer with another, denser start set (more starts among
a larger Halton sample, more turns about a free tool axis), with every unreached target explained.
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np

from design.compose.bounds import PartGeometry, dof_bound, holding_bound, reach_bound, sketch
from design.reach.settings import ReachSettings
from kin.modules import Assembly, AssemblyError, Catalogue

__all__ = ["Verdict", "ComposeSettings", "STAGES", "judge", "assembled", "verify", "robot_targets"]

#: the stages of a verdict, in the order they are tried
STAGES = ("incompatible", "dof", "reach_bound", "holding", "reach", "cycle", "ok")
#: a verdict's stages that are proven (not a search's failure to find)
PROVEN = ("incompatible", "dof", "reach_bound", "holding")
_TOP_WORDS = {0: "no IK solution within the joint limits", 1: "every solution collides (or is too close)",
              2: "every clear solution is inside a singular window", 3: "every clear solution lacks the dexterity"}


@dataclass(frozen=True)
class ComposeSettings:
    """The effort of a composition: the reach study's (``reach``), the verification's (``verify``,
    denser; None: no verification), assemblies judged per batch, the cycle's IK seed."""

    reach: ReachSettings = field(default_factory=ReachSettings)
    verify: ReachSettings | None = field(default_factory=lambda: ReachSettings(starts=16, samples=16384, spins=12,
                                                                                max_iter=300))
    batch: int = 8
    seed: int = 0

    def __post_init__(self):
        if isinstance(self.batch, bool) or not isinstance(self.batch, (int, np.integer)) or not 1 <= self.batch <= 4096:
            raise ValueError(f"batch must be an integer in [1, 4096], got {self.batch!r}")


@dataclass(frozen=True)
class Verdict:
    """One assembly (``assembly``: its text) judged for one part (``part``: its name)."""

    assembly: str
    part: str
    feasible: bool
    stage: str
    reason: str
    reached: int = 0
    targets: int = 0
    cycle_time: float | None = None
    torque_ratio: float | None = None
    seconds: float = 0.0

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


def assembled(catalogue: Catalogue, assembly: Assembly, payload: float = 0.0):
    """The robot (:class:`kin.Chain`) of an assembly, unchecked for holding, named after the
    catalogue; ``payload`` kg more at the tool frame's origin."""
    from kin.modules import assemble
    chain = assemble(catalogue, assembly, name=f"{catalogue.name}_assembly", check_holding=False)
    if payload > 0:
        from kin.dynamics.inertia import LinkInertia
        parts = [p for p in (chain.payload, LinkInertia(payload, (0.0, 0.0, 0.0), body="payload")) if p is not None]
        chain = dataclasses.replace(chain, payload=LinkInertia.combined(parts, body="tool"))
    return chain


def robot_targets(part):
    """The part's targets seen from the robot's base (its placement in the cell undone)."""
    P = np.linalg.inv(part.placement)
    t = part.targets
    if np.allclose(P, np.eye(4), atol=0.0, rtol=0.0):
        return t
    rots = None if t.rotations is None else np.einsum("ij,njk->nik", P[:3, :3], t.rotations)
    return dataclasses.replace(t, positions=t.positions @ P[:3, :3].T + P[:3, 3],
                               axes=None if t.axes is None or rots is not None else t.axes @ P[:3, :3].T,
                               rotations=rots)


def _windows(robot, part):
    if part.windows is None:
        return None
    from kin.singular import analyse_singularities
    from planning.windows import build_windows
    kind, value = part.windows
    analysis = analyse_singularities(robot)
    return build_windows(robot, analysis=analysis, **{kind: value})


def _problem(robot, part, reach: ReachSettings, targets=None, windows=False):
    from design.reach.score import ScoreWeights
    from design.reach.study import ReachProblem
    # the score is not asked for: a fixed dexterity reference saves the sample's Jacobians
    return ReachProblem(robot, part.targets if targets is None else targets, part.cell, part.clearance,
                        _windows(robot, part) if windows is False else windows, ScoreWeights(dexterity_ref=1.0), reach,
                        part.dexterity)


def _farthest_first(robot, part, reach: ReachSettings, windows, far: int):
    """The reach study of the part's one target ``far`` alone — its verdict is the full study's for
    that target when the targets are positions: each target's IK starts are its own nearest sample
    configurations (positions only), its IK runs are its own."""
    from design.task.model import Targets
    t = part.targets
    one = Targets(t.positions[[far]], tolerance=t.tolerance)
    return _problem(robot, part, reach, one, windows).run(part.placement)


#: reach-study outcomes of kinematic twins, per process: (id of the part, settings, twin key) → (reached all,
#: reason, targets reached); the parts (and catalogues, below) are kept alive beside them so that an id is
#: never reused
_TWINS: dict[tuple, tuple[bool, str, int]] = {}
_TWIN_PARTS: dict[int, object] = {}
_TWIN_LIMIT = 200_000
#: each assembly's robot and holding verdict, per process: (id of the catalogue, assembly text) → (chain,
#: holding_bound's reason or None) — the search's screen and every part's verdict ask for the same ones
_HELD: dict[tuple, tuple[object, str | None]] = {}
_HELD_LIMIT = 4096


def held(catalogue: Catalogue, assembly: Assembly):
    """(the assembly's robot, :func:`holding_bound`'s reason or None), built and checked once per process;
    :class:`AssemblyError` if it cannot be assembled."""
    key = (id(catalogue), assembly.text(catalogue))
    hit = _HELD.get(key)
    if hit is None:
        if len(_HELD) >= _HELD_LIMIT:
            _HELD.clear()
        chain = assembled(catalogue, assembly)
        hit = _HELD[key] = (chain, holding_bound(chain))
        _TWIN_PARTS[id(catalogue)] = catalogue
    return hit


def _shape(m) -> tuple:
    """What a module gives the reach study: its frames, travel and capsules — not its mass, torque,
    speed or cost."""
    def b(T):
        return b"" if T is None else np.ascontiguousarray(T, dtype=float).tobytes()
    return (m.kind, m.type, b(m.axis), b(m.out), m.limits, m.proximal.capsules, m.distal.capsules)


def twin_key(catalogue: Catalogue, assembly: Assembly) -> tuple:
    """Assemblies with equal keys are *kinematic twins*: module for module the same frames, travel and
    capsules at the same twists (e.g. a rotary module and its stronger sibling of the same housing).  Their
    robots have the same forward kinematics, joint limits and collision geometry, so the reach study —
    targets, cell, clearance, windows, dexterity, all of them functions of those alone — gives them the
    same verdict; only the holding check and the cycle, which see masses, torques and speeds, differ."""
    return tuple(_shape(catalogue.modules[n]) for n in assembly.modules) + tuple(round(t, 12) for t in assembly.twists)


def _twin(part, settings, key) -> tuple:
    if len(_TWINS) > _TWIN_LIMIT:
        _TWINS.clear()
        _HELD.clear()
        _TWIN_PARTS.clear()
    _TWIN_PARTS[id(part)] = part
    return (id(part), repr(settings.reach), key)


def judge(catalogue: Catalogue, assembly: Assembly, part, settings: ComposeSettings | None = None) -> Verdict:
    """The verdict of ``assembly`` for ``part`` (:class:`design.compose.parts.Part`): module text."""
    import kin
    t0 = time.perf_counter()
    settings = settings or ComposeSettings()
    try:
        text = assembly.text(catalogue)
    except (KeyError, AssemblyError):
        text = " ".join(assembly.modules)
    N = len(part.targets)

    def verdict(stage: str, reason: str, **kw) -> Verdict:
        return Verdict(text, part.name, stage == "ok", stage, reason, targets=N, seconds=time.perf_counter() - t0,
                       **kw)

    try:
        assembly.check(catalogue)
    except AssemblyError as e:
        return verdict("incompatible", str(e))
    g = PartGeometry.of(part)
    sk = sketch(catalogue, assembly.modules, assembly.twists)
    for stage, bound in (("dof", dof_bound), ("reach_bound", reach_bound)):
        why = bound(sk, g)
        if why:
            return verdict(stage, why)
    payload = part.cycle.payload if part.cycle is not None else 0.0
    try:
        chain, why = held(catalogue, assembly)
    except AssemblyError as e:
        return verdict("incompatible", str(e))
    if why:
        return verdict("holding", why)
    tk = _twin(part, settings, twin_key(catalogue, assembly))
    known = _TWINS.get(tk)
    if known is not None and not known[0]:
        return verdict("reach", f"{known[1]} (the reach study of a kinematic twin: the same frames, travel and "
                                "capsules)", reached=known[2])
    robot = kin.Robot(chain, backend="vm")
    if known is not None:
        return _cycle_stage(catalogue, assembly, part, settings, chain, robot, verdict, payload)
    try:
        windows = _windows(robot, part)
        if part.targets.orientation == "free" and N > 1:
            # the target farthest from the first joint alone first: most assemblies miss it
            far = int(np.argmax(np.linalg.norm(g.positions - sk.points[0], axis=1)))
            d = _farthest_first(robot, part, settings.reach, windows, far)
            if not d["reached"][0]:
                why = (f"target {far} (the farthest from the first joint): "
                       f"{_TOP_WORDS.get(int(d['top'][0]), 'not reached')}; the others were not tried")
                _TWINS[tk] = (False, why, 0)
                return verdict("reach", why)
        pb = _problem(robot, part, settings.reach, windows=windows)
    except kin.RmtError as e:
        return verdict("reach", f"the reach study could not be set up: {e}")
    d = pb.run(part.placement)
    reached = np.asarray(d["reached"], bool)
    if not reached.all():
        miss = np.flatnonzero(~reached)
        i = int(miss[0])
        why = (f"reached {int(reached.sum())} of {N} targets; target {i}: "
               f"{_TOP_WORDS.get(int(d['top'][i]), 'not reached')}")
        _TWINS[tk] = (False, why, int(reached.sum()))
        return verdict("reach", why, reached=int(reached.sum()))
    _TWINS[tk] = (True, "", N)
    return _cycle_stage(catalogue, assembly, part, settings, chain, robot, verdict, payload)


def _cycle_stage(catalogue, assembly, part, settings, chain, robot, verdict, payload) -> Verdict:
    """The verdict of an assembly that reaches every target: ok, or the cycle's."""
    import kin
    N = len(part.targets)
    if part.cycle is None:
        return verdict("ok", f"reached all {N} targets", reached=N)
    from design.cycle.evaluate import evaluate_cycle
    from design.task.model import TaskError
    try:
        spec = part.cycle.spec(chain)
    except TaskError as e:
        return verdict("cycle", str(e), reached=N)
    dyn = robot if payload <= 0 else kin.Robot(assembled(catalogue, assembly, payload), backend="vm")
    res = evaluate_cycle(dyn, spec, robot_targets(part), seed=settings.seed)
    if not res.ok:
        return verdict("cycle", f"the cycle's IK reached no solution for target(s) "
                                f"{', '.join(map(str, res.unreached))}", reached=N)
    ratio = None if math.isnan(res.torque_ratio) else float(res.torque_ratio)
    kw = {"reached": N, "cycle_time": float(res.cycle_time), "torque_ratio": ratio}
    if part.max_cycle_time is not None and res.cycle_time > part.max_cycle_time:
        return verdict("cycle", f"cycle time {res.cycle_time:.4g} s > max_cycle_time {part.max_cycle_time:g} s", **kw)
    if not res.within_torque:
        j = int(np.nanargmax(res.torque_ratios))
        return verdict("cycle", f"joint {j + 1} needs {res.peak_torque[j]:.4g} of its {res.tau_max[j]:.4g} "
                                f"(torque ratio {res.torque_ratio:.3g} > 1)", **kw)
    return verdict("ok", f"reached all {N} targets; cycle {res.cycle_time:.4g} s"
                         + (f", torque ratio {ratio:.3g}" if ratio is not None else ""), **kw)


def verify(catalogue: Catalogue, assembly: Assembly, part, settings: ReachSettings):
    """The full reach study (:class:`design.reach.ReachStudy`, reasons explained) of an assembly for a
    part with ``settings`` — another start set than the search's."""
    import kin
    robot = kin.Robot(assembled(catalogue, assembly), backend="vm")
    return _problem(robot, part, settings).study(part.placement)
