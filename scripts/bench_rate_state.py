#!/usr/bin/python3
"""Whole-run benchmark of the rate_state law: writes docs/benchmarks/rate_state.md.

    scripts/bench_rate_state.py [--repeats N]

On one machine in one session, interleaved: pmma_2d (Amontons-Coulomb) and pmma_2d_rate_state over
the same first WINDOW s of loading, the latter with fast-forward and with full dynamics (the error of
fast-forward), and the rate_state block through slide_hold_slide.yaml (holds of up to 100 s). A
window rather than "to the first global event": with rate_state the interface keeps creeping, so no
slip event ends (docs/status.md). Every figure is a ratio against a run of the same session.
"""
import argparse
import csv
import datetime
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from perf_report import cpu_model  # noqa: E402
from sweep import ROOT, RUNNER  # noqa: E402

SCENES = os.path.join(ROOT, "friction_sim/scenes")
PROTOCOLS = os.path.join(ROOT, "friction_sim/protocols")

WINDOW = 0.5  # s of loading
IN_WINDOW = ["--set", "stop.global_events=0", "--set", "stop.time=%g" % WINDOW]

# (label, scene, extra friction_run arguments)
RUNS = [
    ("pmma_2d, fast-forward", "pmma_2d", IN_WINDOW),
    ("pmma_2d_rate_state, fast-forward", "pmma_2d_rate_state", IN_WINDOW),
    ("pmma_2d_rate_state, full dynamics", "pmma_2d_rate_state",
     IN_WINDOW + ["--set", "integrator.fast_forward=false"]),
    ("rate_state block, slide_hold_slide (120 s)", "rate_state",
     ["--protocol", os.path.join(PROTOCOLS, "slide_hold_slide.yaml")]),
]


def summary_field(text, prefix):
    line = next(line for line in text.splitlines() if line.strip().startswith(prefix))
    return line.split(prefix, 1)[1].strip()


def run_once(scene, extra, out):
    subprocess.run([RUNNER, os.path.join(SCENES, scene + ".yaml"), "--out", out] + extra, check=True,
                   stdout=subprocess.DEVNULL)
    summary = open(os.path.join(out, "summary.txt")).read()
    with open(os.path.join(out, "events.csv")) as handle:
        events = list(csv.DictReader(handle))
    simulated = summary_field(summary, "simulated")
    wall = float(summary_field(summary, "wall time").split()[0])
    steps = int(simulated.split(" in ")[1].split()[0])
    with open(os.path.join(out, "loading.csv")) as handle:
        loading = list(csv.DictReader(handle))
    ratios = [float(row["shear_force_N"]) / float(row["normal_force_N"]) for row in loading]
    return {"wall": wall, "steps": steps, "events": len(events), "peak": max(ratios), "last": ratios[-1],
            "sliding": int(loading[-1]["sliding_nodes"]),
            "residual": summary_field(summary, "energy-balance residual (relative):")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2, help="rounds of the interleaved runs (default 2)")
    args = parser.parse_args()
    results = {label: [] for label, _, _ in RUNS}
    with tempfile.TemporaryDirectory() as work:
        for round_index in range(args.repeats):
            for label, scene, extra in RUNS:
                out = os.path.join(work, "%s-%d" % (scene, round_index))
                results[label].append(run_once(scene, extra, out))
                print("%s: %.2f s" % (label, results[label][-1]["wall"]), flush=True)
    best = {label: min(runs, key=lambda r: r["wall"]) for label, runs in results.items()}
    base = best[RUNS[0][0]]["wall"]
    full = best["pmma_2d_rate_state, full dynamics"]
    lines = ["# Benchmark: the rate_state law", "",
             "Written by `scripts/bench_rate_state.py` (%d interleaved rounds; the fastest of each run is shown)."
             % args.repeats, "",
             "- %s; one core per run" % cpu_model(), "- measured on %s" % datetime.date.today().isoformat(), "",
             "| run | wall (s) | × pmma_2d | steps | slip events ended | largest F_X/F_Z | F_X/F_Z at the end | "
             "nodes sliding at the end | energy residual |", "|---|---|---|---|---|---|---|---|---|"]
    for label, _, _ in RUNS:
        r = best[label]
        lines.append("| %s | %.2f | %.1f× | %d | %d | %.5f | %.5f | %d | %s |" % (
            label, r["wall"], r["wall"] / base, r["steps"], r["events"], r["peak"], r["last"], r["sliding"],
            r["residual"]))
    ff = best["pmma_2d_rate_state, fast-forward"]
    lines += ["", "The 2D runs cover the first %g s of loading. Fast-forward against full dynamics with "
              "rate_state: F_X/F_Z at the end %.1e apart." % (WINDOW, abs(ff["last"] - full["last"]))]
    path = os.path.join(ROOT, "docs/benchmarks/rate_state.md")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as handle:
        handle.write("\n".join(lines) + "\n")
    print("written to %s" % path)


if __name__ == "__main__":
    main()
