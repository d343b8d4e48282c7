"""How often :func:`gearcheck.compare.engine.diagnose` names the term that was broken.

    python examples/diagnose_broken_models.py [docs/bring-your-own-model/diagnosis.md]

For each preset, deliberately broken copies of the reference lumped model, one mistake each:

* dropped coupling: one coefficient of one deflection row (bearing, support, coupling, shaft or mesh row) set
  to 0, for every nonzero coefficient of every row;
* sign error: that coefficient's sign flipped, for every one;
* wrong inertia: a member's mass on its transverse translations, its rotational inertia or its axial mass
  times 1.5 and times 0.7 (the member's entries of M), for every member;
* missing gyroscopic terms: G = 0.

Each broken copy gives its evidence to ``diagnose`` twice: in full (modes at rest with shapes and mass matrix,
frequencies at the operating speed), and frequencies only (at rest and at speed).  A hit is a top candidate
(hit top-1) or one of the top three (hit top-3) that names the broken row, the member and its coordinates, or
the gyroscopic terms; an exact hit (exact top-1) also names the coefficient and the kind of mistake, or the
factor to 1e-3.  A candidate's class counts: frequencies alone cannot tell a planet's row from another
planet's, and the diagnosis reports such look-alikes as one class ("top-1 a class of several" counts those).
A mistake that changes no frequency and no shape (the diagnosis says the reference agrees) counts as "no
effect", not as a miss.  "Closest runner-up" is the smallest score of the second-best class over the hits: how
far the broken term stands out, or how much noise the evidence could carry before another term took its place.

The tables and the misses are printed and written between the markers of the markdown file given (the text
around them is written by hand).  The output is deterministic; two worker processes, a few minutes.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # many small eigenproblems: one thread per worker

import sys  # noqa: E402
import time  # noqa: E402
from concurrent.futures import ProcessPoolExecutor  # noqa: E402
from dataclasses import dataclass, replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

import gearcheck  # noqa: E402
from gearcheck.compare.engine import COEFFICIENT_FLOOR, Evidence, diagnose  # noqa: E402
from gearcheck.train import AXIAL  # noqa: E402

PRESETS = ("demo-3p", "demo-4p", "hub-drive", "double-planet", "helical-planetary")
CLASSES = ("dropped coupling", "sign error", "wrong inertia", "missing gyroscopic")
FACTORS = (1.5, 0.7)
BEGIN, END = "<!-- diagnose_broken_models: begin -->", "<!-- diagnose_broken_models: end -->"
EVIDENCE = {"shapes": "modes at rest with shapes, frequencies at speed",
            "frequencies": "frequencies at rest and at speed, no shapes"}
MISSES_SHOWN = 3  # per evidence, class and preset


@dataclass
class Mistake:
    label: str
    kind: str  # the diagnosis' kind that names it exactly
    model: object
    row: str | None = None
    coordinate: str | None = None
    member: str | None = None
    coordinates: tuple[str, ...] = ()
    factor: float | None = None

    def names(self, candidate) -> tuple[bool, bool]:
        """(names the broken thing, names it exactly) for a candidate or one of its equivalents."""
        named = exact = False
        for c in candidate.alike():
            if self.kind == "gyroscopic":
                hit = full = c.kind == "gyroscopic"
            elif self.kind == "inertia":
                hit = c.kind == "inertia" and c.member == self.member and tuple(c.coordinates) == self.coordinates
                full = hit and abs(c.factor - self.factor) <= 1e-3 * self.factor
            else:
                hit = c.row == self.row
                full = hit and c.kind == self.kind and c.coordinate == self.coordinate
            named, exact = named or hit, exact or full
        return named, exact


def row_mistakes(model, kind: str) -> list[Mistake]:
    """Every nonzero coefficient of every row with a stiffness, dropped or flipped."""
    labels = model.dofs.labels()
    out = []
    rows = [(f"row {r.name}", r.name, r.a, i) for i, r in enumerate(model.rows) if r.stiffness]
    rows += [(f"mesh {mesh.id}", mesh.id, a, None) for mesh, a in zip(model.spec.meshes, model.mesh_rows)]
    for prefix, name, a, index in rows:
        for j in np.where(np.abs(a) > COEFFICIENT_FLOOR * np.max(np.abs(a)))[0]:
            broken = a.copy()
            broken[j] = 0.0 if kind == "dropped coupling" else -a[j]
            if index is None:
                mesh_rows = model.mesh_rows.copy()
                mesh_rows[[m.id for m in model.spec.meshes].index(name)] = broken
                copy = replace(model, mesh_rows=mesh_rows)
            else:
                rows_copy = list(model.rows)
                rows_copy[index] = replace(rows_copy[index], a=broken)
                copy = replace(model, rows=rows_copy)
            verb = "dropped" if kind == "dropped coupling" else "flipped"
            out.append(Mistake(f"{prefix}: {labels[j]} {verb}", kind, copy, row=name, coordinate=labels[j]))
    return out


def inertia_mistakes(model) -> list[Mistake]:
    """Every member's transverse mass, rotational inertia and axial mass times 1.5 and 0.7."""
    out = []
    for member in model.spec.members:
        dofs = [d for m, d in model.dofs.names if m == member]
        groups = (("mass", dofs[:2]), ("theta inertia", ["theta"]), ("axial mass", [d for d in dofs if d == AXIAL]))
        for what, group in groups:
            if not group:
                continue
            idx = [model.dofs(member, d) for d in group]
            for factor in FACTORS:
                M = model.M.copy()
                M[idx, idx] *= factor
                out.append(Mistake(f"{member} {what} x {factor}", "inertia", replace(model, M=M), member=member,
                                   coordinates=tuple(f"{member}.{d}" for d in group), factor=factor))
    return out


def mistakes(model, cls: str) -> list[Mistake]:
    if cls == "wrong inertia":
        return inertia_mistakes(model)
    if cls == "missing gyroscopic":
        return [Mistake("G = 0", "gyroscopic", replace(model, G=np.zeros_like(model.G)))]
    return row_mistakes(model, cls)


def run(task: tuple[str, str, str]) -> dict:
    """Every mistake of one class on one preset, diagnosed from one kind of evidence."""
    evidence, preset, cls = task
    model = gearcheck.Train(preset).lumped.model
    counts = dict(instances=0, no_effect=0, top1=0, top3=0, exact=0, classes=0)
    misses, closest = [], None  # closest: (runner-up score, what)
    start = time.process_time()
    for mistake in mistakes(model, cls):
        diagnosis = diagnose(model, Evidence.of_model(mistake.model, shapes=evidence == "shapes"))
        counts["instances"] += 1
        if diagnosis.agrees:
            counts["no_effect"] += 1
            continue
        hits = [mistake.names(c) for c in diagnosis.candidates]
        counts["top1"] += hits[0][0]
        counts["exact"] += hits[0][1]
        counts["top3"] += any(named for named, _ in hits[:3])
        counts["classes"] += bool(diagnosis.best.equivalents)
        runner_up = diagnosis.candidates[1]
        if hits[0][0] and (closest is None or runner_up.score < closest[0]):
            closest = (runner_up.score, f"{mistake.label}: runner-up {runner_up.term}, score {runner_up.score:.2g}")
        if not hits[0][0]:
            found = next((i + 1 for i, (named, _) in enumerate(hits) if named), None)
            misses.append(f"{mistake.label}: named {diagnosis.best.term} (score {diagnosis.best.score:.2g}; "
                          f"the reference {diagnosis.reference_score:.2g})"
                          + (f", the broken term ranks {found}" if found else ", the broken term not in the top 3"))
    return dict(evidence=evidence, preset=preset, cls=cls, counts=counts, misses=misses, closest=closest,
                seconds=time.process_time() - start)


def rate(hits: int, of: int) -> str:
    return f"{hits}/{of} ({100.0 * hits / of:.0f}%)" if of else "-"


def table(results: list[dict]) -> list[str]:
    lines = ["| mistake | preset | instances | no effect | hit top-1 | hit top-3 | exact top-1 "
             "| top-1 a class of several | closest runner-up |", "|---|---|---|---|---|---|---|---|---|"]
    for cls in CLASSES:
        rows = [r for r in results if r["cls"] == cls]
        total = {k: sum(r["counts"][k] for r in rows) for k in rows[0]["counts"]}
        for preset, c, closest in [(r["preset"], r["counts"], r["closest"]) for r in rows] + [("all", total, None)]:
            seen = c["instances"] - c["no_effect"]
            if preset == "all":
                cls_, preset = f"**{cls}**", "**all**"
                closest = min((r["closest"] for r in rows if r["closest"]), default=None)
            else:
                cls_ = cls
            lines.append(f"| {cls_} | {preset} | {c['instances']} | {c['no_effect']} | {rate(c['top1'], seen)} | "
                         f"{rate(c['top3'], seen)} | {rate(c['exact'], seen)} | {c['classes']} | "
                         f"{f'{closest[0]:.2g}' if closest else '-'} |")
    return lines


def report(results: list[dict]) -> str:
    lines = []
    for evidence, what in EVIDENCE.items():
        lines += [f"**Evidence: {what}**", "", *table([r for r in results if r["evidence"] == evidence]), ""]
    lines += ["Hit rates are over the instances with an effect; the closest runner-up is the smallest score of the "
              "second-best class over the hits (how far the broken term stands out). The closest calls:", ""]
    for evidence in EVIDENCE:
        for cls in CLASSES:
            rows = [r for r in results if r["evidence"] == evidence and r["cls"] == cls and r["closest"]]
            if rows:
                r = min(rows, key=lambda r: r["closest"][0])
                lines.append(f"- {evidence}, {cls}, {r['preset']}: {r['closest'][1]}")
    lines += ["", f"Misses (top-1 names another term), the first {MISSES_SHOWN} of each evidence, class and preset:",
              ""]
    misses = [(r, miss) for r in results for miss in r["misses"][:MISSES_SHOWN]]
    lines += [f"- {r['evidence']}, {r['preset']}, {r['cls']}: {miss}" for r, miss in misses] or ["- none"]
    lines += [f"- {r['evidence']}, {r['preset']}, {r['cls']}: ... and {len(r['misses']) - MISSES_SHOWN} more"
              for r in results if len(r["misses"]) > MISSES_SHOWN]
    return "\n".join(lines)


def main(argv: list[str]) -> None:
    order = [(evidence, preset, cls) for evidence in EVIDENCE for cls in CLASSES for preset in PRESETS]
    tasks = sorted(order, key=lambda t: t[1] != "hub-drive")  # the largest first: the two workers finish together
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=2) as pool:
        done = dict(zip(tasks, pool.map(run, tasks)))
    results = [done[task] for task in order]
    table = report(results)
    print(table)
    n = sum(r["counts"]["instances"] for r in results)
    cpu = sum(r["seconds"] for r in results)
    print(f"\n{n} broken models diagnosed in {time.perf_counter() - start:.0f} s ({1e3 * cpu / n:.0f} ms CPU each)",
          file=sys.stderr)
    if argv:
        path = Path(argv[0])
        text = path.read_text(encoding="utf-8")
        head, rest = text.split(BEGIN, 1)
        path.write_text(f"{head}{BEGIN}\n{table}\n{END}{rest.split(END, 1)[1]}", encoding="utf-8")


if __name__ == "__main__":
    main(sys.argv[1:])
