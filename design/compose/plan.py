"""The answer of a reconfiguration (:class:`ReconfigurationPlan`): the base assembly, each part's
assembly and the swaps from the base to it, the modules to own, the costs, and the comparison with
one assembly for every part (:mod:`design.compose.reconfigure`)."""
from __future__ import annotations

from dataclasses import dataclass, field

from design.compose.edits import Edit
from kin.modules import Assembly

__all__ = ["ReconfigurationPlan", "money", "MAX_POOL"]

#: the candidate pool (k × number of parts) is capped at this many assemblies
MAX_POOL = 60


def money(x: float, currency: str = "") -> str:
    """A cost as "21 400 EUR" (thousands spaced; cents only when there are any)."""
    s = f"{round(x):,}" if abs(x - round(x)) < 1e-9 else f"{x:,.2f}"
    return s.replace(",", " ") + (f" {currency}" if currency else "")


@dataclass
class ReconfigurationPlan:
    """A base assembly and each part's assembly (``assemblies``, same order as ``parts``), the swaps
    from the base to each (``edits``; ``operations`` as text), the modules to own (``inventory``:
    name → count, catalogue order) and the costs; the best single assembly serving every part
    (``single``, or None: none does) for comparison — ``single_scope`` says of what it is the least:
    "space" (the composition searched the whole space), "below" (it searched every assembly costing
    up to ``single_floor``, the plan's total, and found none: the single is the least candidate),
    "candidates" (only the candidates were judged).  ``exact``: the optimum over the candidates is
    proven; ``capped``: fewer than the asked ``k`` candidates per part were used.
    ``missing``: parts with no feasible candidate (then there is no plan: ``base`` is None)."""

    catalogue: str
    currency: str
    parts: tuple[str, ...]
    swap_cost: float
    base: Assembly | None
    base_text: str
    assemblies: tuple[Assembly | None, ...]
    texts: tuple[str, ...]
    edits: tuple[tuple[Edit, ...], ...]
    operations: tuple[tuple[str, ...], ...]
    inventory: dict[str, int]
    inventory_cost: float
    swaps: int
    total: float
    single: Assembly | None
    single_text: str
    single_cost: float | None
    pool: tuple[tuple[str, float, tuple[str, ...]], ...]     # (assembly, cost, parts it serves)
    k: int
    k_asked: int
    exact: bool
    nodes: int
    verdicts: int
    missing: tuple[str, ...] = ()
    single_counts: dict[str, int] = field(default_factory=dict)
    single_scope: str = "candidates"
    single_floor: float | None = None
    max_pool: int = MAX_POOL
    notes: tuple[str, ...] = ()
    verification: tuple[tuple[str, int, int], ...] = ()     # (part, reached, targets) by the denser study

    @property
    def found(self) -> bool:
        return self.base is not None

    @property
    def capped(self) -> bool:
        return self.k < self.k_asked

    def _m(self, x: float) -> str:
        return money(x, self.currency)

    def _scope(self) -> str:
        """Where the single assembly is the least of."""
        if self.single_scope == "space":
            return "the least in the space"
        if self.single_scope == "below":
            return f"the least among the candidates; none of the space up to {self._m(self.single_floor)} serves them"
        return "the least among the candidates"

    def comparison(self, short: bool = False) -> str:
        """Which is cheaper, the reconfigurable plan or one assembly for every part, and why
        (``short``: without restating the plan's cost, as :meth:`lines` has it the line before)."""
        m = len(self.parts)
        every = f"all {m} parts" if m > 2 else ("both parts" if m == 2 else "the part")
        if not self.found:
            return (f"no plan: {', '.join(self.missing)} {'has' if len(self.missing) == 1 else 'have'} no feasible "
                    f"assembly among the candidates searched")
        s = "s" if self.swaps != 1 else ""
        plan = (f"the reconfigurable plan costs {self._m(self.inventory_cost)} + {self.swaps} swap{s} × "
                f"{self._m(self.swap_cost)} = {self._m(self.total)}")
        if self.single is None:
            none = {"space": f"no assembly of the space serves {every}",
                    "below": f"no assembly of the space costing up to {self._m(self.single_floor or 0.0)} (the plan's "
                             f"total) serves {every}"}.get(self.single_scope, f"no candidate assembly serves {every} "
                                                                              f"(of {len(self.pool)} judged for every "
                                                                              f"part)")
            return none + ("" if short else f"; {plan}")
        if self.swaps == 0:
            return f"one assembly serves {every} at {self._m(self.single_cost)} ({self._scope()}): no swap pays at " \
                   f"{self._m(self.swap_cost)} a swap"
        extra = [f"{n} ×{c} where the plan owns {self.inventory.get(n, 0)}"
                 for n, c in self.single_counts.items() if c > self.inventory.get(n, 0)]
        why = f": one assembly needs {', '.join(extra)}" if extra else ""
        saves = self._m(self.single_cost - self.total)
        if short:
            return f"one assembly for {every}: {self.single_text} at {self._m(self.single_cost)} ({self._scope()}); " \
                   f"the plan is {saves} cheaper{why}"
        return f"one assembly serves {every} at {self._m(self.single_cost)} ({self.single_text}, {self._scope()}); " \
               f"{plan}, {saves} less{why}"

    def lines(self) -> list[str]:
        """The plan as text (the CLI prints these)."""
        head = (f"reconfiguration for {len(self.parts)} part{'s' if len(self.parts) != 1 else ''} "
                f"(catalogue {self.catalogue}, {self._m(self.swap_cost)} a swap):")
        out = [head]
        if not self.found:
            return [*out, f"  {self.comparison()}"]
        out.append(f"  base assembly: {self.base_text}")
        for name, ops in zip(self.parts, self.operations):
            if not ops:
                out.append(f"  {name}: the base as it is")
            else:
                out.append(f"  {name}: {len(ops)} swap{'s' if len(ops) != 1 else ''}: {'; '.join(ops)}")
        owned = ", ".join(f"{n} ×{c}" for n, c in self.inventory.items() if c)
        out.append(f"  modules to own: {owned} = {self._m(self.inventory_cost)}")
        out.append(f"  total: {self._m(self.inventory_cost)} + {self.swaps} swap{'s' if self.swaps != 1 else ''} × "
                   f"{self._m(self.swap_cost)} = {self._m(self.total)}")
        out.append(f"  {self.comparison(short=True)}")
        how = "exact" if self.exact else f"not proven least (search stopped after {self.nodes} nodes)"
        cap = f"; k capped from {self.k_asked} to {self.k} (k × parts ≤ {self.max_pool})" if self.capped else ""
        if self.verification:
            out.append("  verified (denser reach study): " + ", ".join(
                f"{p} {r}/{n}" + ("" if r == n else " NOT CONFIRMED") for p, r, n in self.verification))
        out.append(f"  {how} over {len(self.pool)} candidate assemblies (up to {self.k} feasible per part, cheapest "
                   f"first{cap}; {self.verdicts} verdicts for the other parts)")
        out.extend(f"  note: {n}" for n in self.notes)
        return out

    def to_json(self) -> dict:
        return {
            "catalogue": self.catalogue, "currency": self.currency, "parts": list(self.parts),
            "swap_cost": self.swap_cost, "found": self.found, "missing": list(self.missing),
            "base": self.base_text if self.found else None,
            "configurations": [{"part": p, "assembly": t, "swaps": len(ops), "operations": list(ops)}
                               for p, t, ops in zip(self.parts, self.texts, self.operations)] if self.found else [],
            "inventory": dict(self.inventory), "inventory_cost": self.inventory_cost if self.found else None,
            "swaps": self.swaps if self.found else None, "total": self.total if self.found else None,
            "single": ({"assembly": self.single_text, "cost": self.single_cost} if self.single is not None else None),
            "single_scope": self.single_scope, "single_floor": self.single_floor,
            "comparison": self.comparison(), "exact": self.exact, "k": self.k, "k_asked": self.k_asked,
            "capped": self.capped, "nodes": self.nodes, "verdicts": self.verdicts, "notes": list(self.notes),
            "verification": [{"part": p, "reached": r, "targets": n} for p, r, n in self.verification],
            "pool": [{"assembly": t, "cost": c, "serves": list(s)} for t, c, s in self.pool],
        }
