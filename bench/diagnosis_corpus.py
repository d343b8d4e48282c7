"""How often the diagnosis names the mistake in broken models from independent formulations.

The corpus of :mod:`gearcheck.compare.studies.diagnosis_corpus` (Lin & Parker 1999 and torsional formulations of
demo-3p and demo-4p, written apart from gearcheck's assembly, broken as the literature's slips break them) is
diagnosed against the reference; printed: the unbroken formulations' agreement with the reference, the hit-rate
table by class (right term named first, over the cases with an effect; median margin to the runner-up; rigid-body
modes lost or gained reported), the cases without effect, the misses, and the time.

    python bench/diagnosis_corpus.py [TRAIN ...] [--frequencies-only]

``--frequencies-only`` drops the shapes from the evidence: then a planet's row and the same row of another
planet look alike (cyclic symmetry), and "in the first class" counts the right term among the look-alikes.
"""

from __future__ import annotations

import argparse
import time

from gearcheck.compare.studies.diagnosis_corpus import TRAINS, agreement, cases, run, table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trains", nargs="*", default=list(TRAINS))
    parser.add_argument("--frequencies-only", action="store_true", help="evidence without mode shapes")
    args = parser.parse_args()
    trains = tuple(args.trains)
    for train in trains:
        for shaft in (True, False):
            for name, best in agreement(train, shaft).items():
                parts = ", ".join(f"{k} {v:.1e}" for k, v in best.parts.items())
                print(f"unbroken {name} {train}{'' if shaft else ' (free input)'}: {best.kind}, {parts}")
    start = time.perf_counter()
    outcomes = [run(case, shapes=not args.frequencies_only) for case in cases(trains)]
    elapsed = time.perf_counter() - start
    print()
    print("\n".join(table(outcomes)))
    print("\nCases without effect:")
    for o in (o for o in outcomes if not o.effect):
        print(f"- {o.case.train}, {o.case.formulation}: {o.case.mistake}: {o.case.what}")
    misses = [o for o in outcomes if o.effect and not o.hit]
    print("\nMisses (another term named first):" + ("" if misses else " none"))
    for o in misses:
        print(f"- {o.case.train}, {o.case.mistake}: {o.case.what}: named {o.diagnosis.best.term} "
              f"(score {o.diagnosis.best.score:.3g})")
    print(f"\n{len(outcomes)} diagnoses in {elapsed:.1f} s ({elapsed / len(outcomes):.2f} s each)")


if __name__ == "__main__":
    main()
