#!/usr/bin/python3
"""The side-driven chain's time-step convergence table: writes docs/benchmarks/chain_time_step.md.

    scripts/chain_convergence.py [--jobs N]

Runs sweeps/chain_time_step.yaml (pmma_1d_side to its first global event with velocity Verlet and RK4,
dt from 2e-7 to 6.25e-9 s, fast-forward off and on) and compares every run's precursor sequence with the
reference, RK4 at the finest step with full dynamics: how many onsets from the first agree within
ONSET_TOLERANCE in F_X/F_Z, the largest onset difference, µ_s,macro's difference and the wall time. The
chain scenes' default integrator is chosen from it (docs/scenes.md).
"""
import argparse
import datetime
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from perf_report import cpu_model  # noqa: E402
from sweep import ROOT, first_global, precursors, run  # noqa: E402

SWEEP = os.path.join(ROOT, "sweeps/chain_time_step.yaml")
OUT = os.path.join(ROOT, "docs/benchmarks/chain_time_step.md")
ONSET_TOLERANCE = 1e-3
KEYS = ("integrator.scheme", "integrator.time_step", "integrator.fast_forward")


def wall_time(run_name):
    with open(os.path.join(ROOT, "sweeps/chain_time_step/runs", run_name, "summary.txt")) as handle:
        return float(re.search(r"wall time ([0-9.e+-]+) s", handle.read()).group(1))


def compare(events, reference):
    """(precursors, onsets agreeing from the first, largest onset difference over the common ones,
    |Δµ_s,macro|) of one run against the reference."""
    mine = [float(e["shear_ratio"]) for e in precursors(events)]
    theirs = [float(e["shear_ratio"]) for e in precursors(reference)]
    differences = [abs(a - b) for a, b in zip(mine, theirs)]
    agreeing = next((i for i, d in enumerate(differences) if d > ONSET_TOLERANCE), len(differences))
    macro = abs(float(first_global(events)["peak_shear_ratio"]) - float(first_global(reference)["peak_shear_ratio"]))
    return len(mine), agreeing, max(differences, default=0.0), macro


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", default=None)
    args = parser.parse_args()
    rows, failed = run(SWEEP, args.jobs)
    if failed:
        sys.exit("chain_convergence: failed runs %s" % failed)
    runs = {}
    for row in rows:
        runs.setdefault(tuple(str(row[key]) for key in KEYS) + (row["run"],), []).append(row)
    finest = min(float(key[1]) for key in runs)
    reference_key = next(k for k in runs if k[0] == "rk4" and float(k[1]) == finest and k[2] == "False")
    reference = runs[reference_key]
    lines = ["# Benchmark: the side-driven chain's time step", "",
             "Written by `scripts/chain_convergence.py` from `sweeps/chain_time_step.yaml`: `pmma_1d_side` to its "
             "first global event. Reference: RK4 at %g s with full dynamics (%d precursors, µ_s,macro %.5f). "
             "*Agreeing*: precursor onsets from the first whose F_X/F_Z is within %g of the reference's." % (
                 finest, len(precursors(reference)), float(first_global(reference)["peak_shear_ratio"]),
                 ONSET_TOLERANCE), "",
             "- %s; one core per run (two runs at a time)" % cpu_model(),
             "- measured on %s" % datetime.date.today().isoformat(), "",
             "| integrator | dt (s) | fast-forward | precursors | agreeing | largest onset difference | "
             "µ_s,macro difference | wall (s) |", "|---|---|---|---|---|---|---|---|"]
    for key in sorted(runs, key=lambda k: (k[0] != "velocity_verlet", -float(k[1]), k[2])):
        count, agreeing, largest, macro = compare(runs[key], reference)
        lines.append("| %s | %g | %s | %d | %d | %.1e | %.1e | %.3g |" % (
            key[0], float(key[1]), "on" if key[2] == "True" else "off", count, agreeing, largest, macro,
            wall_time(key[3])))
    with open(OUT, "w") as handle:
        handle.write("\n".join(lines) + "\n")
    print("written to %s" % OUT)


if __name__ == "__main__":
    main()
