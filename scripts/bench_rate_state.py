#!/usr/bin/python3
"""Whole-run benchmark of the rate_state law: writes docs/benchmarks/rate_state.md.

    scripts/bench_rate_state.py [--repeats N]

On one machine in one session, interleaved: pmma_2d (Amontons-Coulomb) and pmma_2d_rate_state to
their first global event, the latter with fast-forward and with full dynamics (the error of
fast-forward), and the rate_state block through slide_hold_slide.yaml (holds of up to 100 s). Every
figure is a ratio against a run of the same session.
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
from sweep import ROOT, RUNNER, extended_precursors, first_global, precursors  # noqa: E402

SCENES = os.path.join(ROOT, "friction_sim/scenes")
PROTOCOLS = os.path.join(ROOT, "friction_sim/protocols")

# (label, scene, extra friction_run arguments)
RUNS = [
    ("pmma_2d, fast-forward", "pmma_2d", []),
    ("pmma_2d_rate_state, fast-forward", "pmma_2d_rate_state", []),
    ("pmma_2d_rate_state, full dynamics", "pmma_2d_rate_state", ["--set", "integrator.fast_forward=false"]),
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
    time_step = float(simulated.split(" steps of ")[1].split()[0])
    # Events are always stepped by the dynamics: their steps are the floor that no fast-forward removes.
    event_time = sum(float(e["end_time_s"]) - float(e["onset_time_s"]) for e in events)
    with open(os.path.join(out, "loading.csv")) as handle:
        peak = max(float(row["shear_force_N"]) / float(row["normal_force_N"]) for row in csv.DictReader(handle))
    return {"wall": wall, "steps": steps, "event_time": event_time, "event_steps": event_time / time_step, "events": len(events), "precursors": precursors(events),
            "global": first_global(events), "peak": peak,
            "residual": summary_field(summary, "energy-balance residual (relative):")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2, help="rounds of the interleaved runs (default 2)")
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error("--repeats: value %d is not allowed; allowed: an integer >= 1" % args.repeats)
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
             "| run | wall (s) | × pmma_2d | steps | of them in events | slip events | precursors | µ_s,macro | "
             "largest F_X/F_Z | energy residual |", "|---|---|---|---|---|---|---|---|---|---|"]
    for label, _, _ in RUNS:
        r = best[label]
        macro = "%.5f" % float(r["global"]["peak_shear_ratio"]) if r["global"] else "-"
        lines.append("| %s | %.2f | %.1f× | %d | %.0f | %d | %d | %s | %.5f | %s |" % (
            label, r["wall"], r["wall"] / base, r["steps"], r["event_steps"], r["events"], len(r["precursors"]),
            macro, r["peak"], r["residual"]))
    ff = best["pmma_2d_rate_state, fast-forward"]
    base_step = base / best[RUNS[0][0]]["steps"]
    lines += ["", "The floor: the rate_state slider's events alone, stepped at pmma_2d's cost per step (%.0f µs), "
              "would take %.1f× pmma_2d's whole run; at its own cost per step (%.0f µs), %.1f×. Fast-forward "
              "handles everything between events; what is left is the events' own dynamics, slow fronts that "
              "last %.2f ms each on average against pmma_2d's %.2f ms." % (
                  base_step * 1e6, ff["event_steps"] * base_step / base, ff["wall"] / ff["steps"] * 1e6,
                  ff["event_steps"] * ff["wall"] / ff["steps"] / base,
                  ff["event_time"] * 1e3 / max(ff["events"], 1),
                  best[RUNS[0][0]]["event_time"] * 1e3 / max(best[RUNS[0][0]]["events"], 1))]
    def onsets(run):
        return [float(e["shear_ratio"]) for e in extended_precursors(run["precursors"])]

    # Matched by onset, not by rank: full dynamics at this step adds single-node events early in the
    # loading (they go when the step is halved), which would shift a pairing by rank.
    distances = [min(abs(a - b) for b in onsets(full)) for a in onsets(ff)] if onsets(full) else []
    lines += ["", "The 2D runs go to their first global event. Fast-forward against full dynamics with rate_state: "
              "µ_s,macro %.1e apart; %d and %d precursors with L_p > 0; each of fast-forward's has one of full "
              "dynamics' within %.1e in onset F_X/F_Z (median %.1e)." % (
                  abs(float(ff["global"]["peak_shear_ratio"]) - float(full["global"]["peak_shear_ratio"])),
                  len(onsets(ff)), len(onsets(full)), max(distances, default=0.0),
                  sorted(distances)[len(distances) // 2] if distances else 0.0)]
    path = os.path.join(ROOT, "docs/benchmarks/rate_state.md")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as handle:
        handle.write("\n".join(lines) + "\n")
    print("written to %s" % path)


if __name__ == "__main__":
    main()
