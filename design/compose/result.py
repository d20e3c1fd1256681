"""The answer of a composition (:class:`ComposeResult`): the least-cost assemblies found with their
verdicts per part, the verification of the answer, and the accounting of the space — how many
assemblies were never formed (connectors that do not meet, twists proven equivalent), proven empty
by each bound, judged, left as costlier, or (under a budget) not judged."""
from __future__ import annotations

from dataclasses import dataclass, field

from design.compose.verdict import Verdict
from kin.modules import Assembly

__all__ = ["ComposeResult", "Found", "Verification", "COUNT_KEYS"]

#: the counts of a result: the space (``total`` assemblies, ``equivalent`` twist variants left out,
#: module ``sequences`` of the structure and how many of them are ``incompatible``) and where every
#: assembly of ``total`` went: ``dof``, ``reach_bound``, ``holding`` (proven empty), ``evaluated``
#: (judged; ``infeasible`` of them), ``not_cheaper`` (after the answer in cost order) and
#: ``not_judged`` (skipped by a budget) — these six add up to ``total``
COUNT_KEYS = ("total", "equivalent", "sequences", "incompatible", "dof", "reach_bound", "holding", "evaluated",
              "infeasible", "not_cheaper", "not_judged")


@dataclass(frozen=True)
class Found:
    """A feasible assembly: its text (``rmt assemble --modules``), exact cost, verdict per part."""

    assembly: Assembly
    text: str
    cost: float
    joints: int
    verdicts: dict[str, Verdict]


@dataclass(frozen=True)
class Verification:
    """The answer's reach study for one part with another start set: reached of targets, the
    settings, the reasons of the unreached."""

    part: str
    reached: int
    targets: int
    starts: int
    samples: int
    spins: int
    reasons: dict[str, int]

    @property
    def ok(self) -> bool:
        return self.reached == self.targets


@dataclass
class ComposeResult:
    """See the module text.  ``found`` in cost order (the answer first); ``exhaustive``: every
    assembly up to the answer's cost (the whole space when none is found) was judged or proven empty;
    ``frontier``: the cost below which the search was exhaustive."""

    catalogue: str
    currency: str
    parts: list[str]
    space: str
    found: list[Found]
    counts: dict[str, int]
    exhaustive: bool
    frontier: float | None
    examples: dict[str, str] = field(default_factory=dict)
    verification: list[Verification] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    batches: int = 0

    @property
    def best(self) -> Assembly | None:
        return self.found[0].assembly if self.found else None

    @property
    def cost(self) -> float | None:
        return self.found[0].cost if self.found else None

    @property
    def verdicts(self) -> dict[str, Verdict]:
        return self.found[0].verdicts if self.found else {}

    def accounting(self) -> str:
        """The space in one line (where every assembly went)."""
        c = self.counts
        judged = f"judged {c['evaluated']} ({c['infeasible']} infeasible)"
        line = (f"space {c['total']} assemblies ({c['sequences']} module sequences of the structure, "
                f"{c['incompatible']} with connectors that do not meet: never formed"
                + (f"; {c['equivalent']} twist variants proven equivalent: left out" if c["equivalent"] else "")
                + f"); proven empty: dof {c['dof']}, reach bound {c['reach_bound']}, holding {c['holding']}; {judged}")
        if self.found:
            line += f"; {c['not_cheaper']} not cheaper, not needed"
        if c["not_judged"]:
            line += f"; {c['not_judged']} not judged (budget)"
        return line

    def lines(self) -> list[str]:
        """The summary ``rmt compose`` prints."""
        cur = f" {self.currency}" if self.currency else ""
        out = [f"compose: catalogue {self.catalogue}, parts {', '.join(self.parts)}; {self.space}"]
        if self.found:
            f = self.found[0]
            head = "least cost" if self.exhaustive else "best found (not proven least: the search was cut)"
            out.append(f"{head}: {f.cost:g}{cur}, {f.joints} joints: {f.text}")
            for name in self.parts:
                v = f.verdicts.get(name)
                if v is None:
                    continue
                cyc = "" if v.cycle_time is None else f", cycle {v.cycle_time:.4g} s"
                tr = "" if v.torque_ratio is None else f", torque ratio {v.torque_ratio:.3g}"
                out.append(f"  part {name}: reached {v.reached}/{v.targets}{cyc}{tr}")
            for extra in self.found[1:]:
                out.append(f"next: {extra.cost:g}{cur}, {extra.joints} joints: {extra.text}")
        else:
            out.append("no feasible assembly" + (" in the space" if self.exhaustive else " found"))
        out.append(self.accounting())
        if self.exhaustive:
            out.append("exhaustive: every assembly " + ("cheaper than the answer (or as cheap and before it in "
                                                        "order)" if self.found else "of the space")
                       + " was judged or proven empty")
        else:
            c = self.counts
            upto = f" of cost ≤ {self.found[0].cost:g}{cur}" if self.found else ""
            out.append(f"not exhaustive: {c['not_judged']} assemblies{upto} not judged (a stated heuristic: "
                       + (f"exhaustive below cost {self.frontier:g}{cur})" if self.frontier is not None else
                          "nothing was exhaustive)"))
        for stage, why in self.examples.items():
            out.append(f"  e.g. {stage.replace('_', ' ')}: {why}")
        for v in self.verification:
            state = "confirmed" if v.ok else "NOT confirmed"
            why = "" if v.ok else " (" + ", ".join(f"{k} {n}" for k, n in v.reasons.items() if k != "reached") + ")"
            out.append(f"verified: part {v.part}: reached {v.reached}/{v.targets} with {v.starts} starts among "
                       f"{v.samples} samples, {v.spins} turns about a free axis — {state}{why}")
        out += [f"note: {n}" for n in self.notes]
        out.append(f"time {self.seconds:.1f} s, {self.batches} batch(es)")
        return out

    def to_dict(self) -> dict:
        return {"catalogue": self.catalogue, "currency": self.currency, "parts": list(self.parts),
                "space": self.space, "found": self.found is not None and bool(self.found),
                "best": None if not self.found else self.found[0].text,
                "cost": self.cost,
                "assemblies": [{"modules": f.text, "cost": f.cost, "joints": f.joints,
                                "verdicts": {k: v.to_dict() for k, v in f.verdicts.items()}} for f in self.found],
                "counts": dict(self.counts), "exhaustive": self.exhaustive, "exhaustive_below_cost": self.frontier,
                "examples": dict(self.examples),
                "verification": [{"part": v.part, "reached": v.reached, "targets": v.targets, "starts": v.starts,
                                  "samples": v.samples, "spins": v.spins, "reasons": v.reasons, "ok": v.ok}
                                 for v in self.verification],
                "notes": list(self.notes), "seconds": self.seconds, "batches": self.batches}
