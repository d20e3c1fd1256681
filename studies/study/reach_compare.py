"""A report comparing two reach studies of the same targets (:func:`design.reach.compare_studies`):
the headline numbers side by side, the targets gained and lost, the reasons that changed, the two
score maps next to each other and a 3-D view of the targets coloured by what changed — one
:class:`studies.report.document.Document`, rendered by :func:`studies.report.html.render`."""
from __future__ import annotations

import numpy as np

from studies.plots.figure import png_bytes
from studies.plots.reach_compare import comparison_figure
from studies.report.document import Document, Figure, Finding, Paragraph, Section, Table, View3D
from studies.report.reach_compare import comparison_view

__all__ = ["comparison_document"]


def comparison_document(cmp, length_scale: float = 1.0, length_unit: str = "m", sources=("", "")) -> Document:
    """The comparison as a report document (render it with :func:`studies.report.html.render`)."""
    la, lb = cmp.labels
    a, b = cmp.a, cmp.b
    d = cmp.to_dict()
    doc = Document(title=f"Reach: {la} against {lb}",
                   summary=f"{len(cmp.gained)} targets; {la}: {100 * a.coverage:.1f} % reached, {lb}: "
                           f"{100 * b.coverage:.1f} %.")
    doc.findings = [Finding(f"{lb} reaches {len(d['gained'])} target(s) {la} misses and misses {len(d['lost'])} "
                            f"that {la} reaches; mean score {a.mean_score:.3f} → {b.mean_score:.3f} "
                            f"({d['mean_score_change']:+.3f}; over the {d['reached_by_both']} both reach: "
                            f"{d['mean_score_change_both']:+.3f}).", ok=not d["lost"])]

    def place(st):
        from kin.transforms import matrix_to_rpy
        x = st.placement[:3, 3] / length_scale
        r = np.degrees(matrix_to_rpy(st.placement[:3, :3])) + 0.0        # no "−0"
        return f"({', '.join(f'{v:.4g}' for v in x)}) {length_unit}, rpy ({', '.join(f'{v:.3g}' for v in r)})°"

    rows = [["robot", a.robot, b.robot], ["cell", a.cell or "—", b.cell or "—"],
            ["placement", place(a), place(b)], ["reached (%)", 100 * a.coverage, 100 * b.coverage],
            ["mean score", a.mean_score, b.mean_score], ["fragile (reached from one start)", int(a.fragile.sum()),
                                                         int(b.fragile.sum())]]
    for reason in sorted(set(a.reason_counts()) | set(b.reason_counts())):
        rows.append([f"targets: {reason.replace('_', ' ')}", a.reason_counts().get(reason, 0),
                     b.reason_counts().get(reason, 0)])
    sec = Section("Side by side")
    if any(sources):
        sec.blocks.append(Paragraph(f"{la}: `{sources[0]}`; {lb}: `{sources[1]}`."))
    sec.blocks.append(Table(["", la, lb], rows, "The two studies' headline numbers.", fmt=".4g"))
    sec.blocks.append(Figure("reach_compare", png_bytes(comparison_figure(cmp, length_scale, length_unit)),
                             "Left and middle: each study's score per target (grey ×: missed), in the plane the "
                             "targets spread over most; right: what changed."))
    sec.blocks.append(View3D("reach_compare_3d", comparison_view(cmp, length_scale, length_unit),
                             "The targets in 3-D, coloured by what changed; hover for the score change."))
    doc.sections.append(sec)
    ch = Section("Targets that changed")
    changes = [[r["from"].replace("_", " "), r["to"].replace("_", " "), r["targets"]] for r in d["reason_changes"]]
    ch.blocks.append(Table(["reason in " + la, "reason in " + lb, "targets"], changes or [["—", "—", 0]],
                           "Targets whose verdict or reason differs."))
    listed = [[int(i), *(a.positions[i] / length_scale), a.reason[i], b.reason[i], a.score[i], b.score[i]]
              for i in np.flatnonzero(cmp.gained | cmp.lost)[:200]]
    if listed:
        ch.blocks.append(Table(["target", f"x ({length_unit})", f"y ({length_unit})", f"z ({length_unit})",
                                f"reason ({la})", f"reason ({lb})", f"score ({la})", f"score ({lb})"], listed,
                               "The targets gained or lost (at most 200 listed).", fmt=".4g"))
    doc.sections.append(ch)
    return doc
