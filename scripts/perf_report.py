#!/usr/bin/python3
"""Regenerates docs/PERFORMANCE.md: the same scenes in every mode, wall time against error.

    scripts/perf_report.py [--quick]

Runs the offline runner (friction_run) on pmma_2d to its first global event in each mode (integrator
x dt x fast-forward x spring form), compares every mode with a reference run (Verlet, dt = 50 ns,
full dynamics), measures the fast-forward at two stage speeds and over lattice sizes, runs the Google
Benchmark of the step, and writes the report with a Pareto plot (docs/figures/pareto.png).
"""
import argparse
import csv
import json
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import time

import matplotlib
import yaml

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sweep import ROOT, RUNNER as RUN, first_global, precursors  # noqa: E402

BENCH = os.path.join(ROOT, ".build/devel/lib/friction_sim/bench_kernels")
SCENE = os.path.join(ROOT, "friction_sim/scenes/pmma_2d.yaml")
OUT = os.path.join(ROOT, ".build/perf")
REPORT = os.path.join(ROOT, "docs/PERFORMANCE.md")
# The section scripts/perf_side_by_side.py writes (this build against the one before, as ratios): kept
# when this script rewrites the rest of the report.
SIDE_BY_SIDE = ("<!-- side by side: written by scripts/perf_side_by_side.py -->", "<!-- side by side: end -->")
# The geometric lattices ("nx/nz") of bench_kernels' latticeStep from 10³ to 10⁶ nodes whose runs of
# nx − 1 bonds are whole 8-wide vectors, as in every lattice the scenes use (57, 113, 225, 449 and 1401
# wide): their costs tell how the step scales with the number of nodes. A run's left-over bonds cost
# extra at any size, most in short rows: REMAINDER_SIZE, also 10³ nodes, is reported beside them.
LATTICE_SIZES = ["33/31", "57/31", "113/61", "225/121", "449/241", "1001/61", "1001/1001"]
REMAINDER_SIZE = "32/32"
# The lattices a naive step of the same bulk (benchmarks/naive_lattice.h) is measured on, for scale.
NAIVE_SIZES = ["57/31", "225/121", "1001/1001"]
# The lattices stepped on two threads (latticeStepOnThreads), against latticeStep on one.
THREADED_SIZES = ["57/31", "113/61", "225/121", "449/241", "1001/1001"]
# Its name in Google Benchmark's results (it measures real time: the threads' CPU time would mislead).
THREADED_CASE = "latticeStepOnThreads/%s/2/real_time"
# The cases the report reads by name: a bench_kernels built before one of them was added is refused at
# the start rather than at the end of the run.
REQUIRED_CASES = (["latticeStep/geometric/" + size for size in LATTICE_SIZES + [REMAINDER_SIZE]] +
                  ["latticeStep/linearised/57/31", "chainStep/2", "chainStep/57", "chainStep/1000",
                   "stateStream/1767", "stateStream/1002001", "leapfrogStream/1767", "leapfrogStream/1002001",
                   "bondDividerFloor"] +
                  [case + size for size in NAIVE_SIZES for case in ("naiveLatticeStep/", "latticeStepOneAtATime/")] +
                  [THREADED_CASE % size for size in THREADED_SIZES])


def size_label(size):
    """'57 × 31' for '57/31'."""
    return size.replace("/", " × ")


def run_length(size):
    """The bonds in each of a lattice's runs of nx − 1 (the horizontal and diagonal families)."""
    return int(size.split("/")[0]) - 1


def left_over_bonds(size):
    """The bonds of each run of nx − 1 that are not in a whole 8-wide vector."""
    return run_length(size) % 8


def flatness(median, sizes):
    """The median cost of `sizes` and the largest relative distance of one of them from it (None if one
    is missing)."""
    costs = [median.get("latticeStep/geometric/" + size) for size in sizes]
    if None in costs:
        return math.nan, None
    sizes_median = statistics.median(costs)
    return sizes_median, max(abs(cost / sizes_median - 1) for cost in costs)


def run(name, settings, timeout=None):
    """One offline run (reused if .build/perf/<name> already holds it); None if it timed out."""
    out = os.path.join(OUT, name)
    args = [RUN, SCENE, "--out", out]
    for key, value in settings.items():
        args += ["--set", "%s=%s" % (key, value)]
    marker = os.path.join(out, "timed_out")
    if os.path.exists(marker):
        return None
    if not os.path.exists(os.path.join(out, "summary.txt")):
        try:
            subprocess.run(args, check=True, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            os.makedirs(out, exist_ok=True)
            open(marker, "w").close()
            return None
    with open(os.path.join(out, "summary.txt")) as handle:
        summary = handle.read()
    wall = float(re.search(r"wall time ([0-9.e+-]+) s", summary).group(1))
    steps = int(re.search(r"in ([0-9]+) steps", summary).group(1))
    residual = float(re.search(r"residual \(relative\): ([-0-9.e+na]+)", summary).group(1))
    with open(os.path.join(out, "events.csv")) as handle:
        events = list(csv.DictReader(handle))
    nodes = 57 * 31
    if "lattice.nodes_x" in settings:
        nodes = int(settings["lattice.nodes_x"]) * int(settings["lattice.nodes_z"])
    return {"name": name, "settings": settings, "wall": wall, "steps": steps, "residual": residual,
            "events": events, "nodes": nodes}


def errors(result, reference):
    mine, ref = precursors(result["events"]), precursors(reference["events"])
    shear = max([abs(float(a["onset_shear_force_N"]) / float(b["onset_shear_force_N"]) - 1) for a, b in zip(mine, ref)]
                + [0.0])
    length = max([abs(float(a["rupture_length_m"]) - float(b["rupture_length_m"])) for a, b in zip(mine, ref)] + [0.0])
    g, gr = first_global(result["events"]), first_global(reference["events"])
    macro = abs(float(g["peak_shear_ratio"]) / float(gr["peak_shear_ratio"]) - 1) if g and gr else math.nan
    speed = (abs(float(g["median_front_speed_m_s"]) / float(gr["median_front_speed_m_s"]) - 1)
             if g and gr else math.nan)
    return {"precursors": len(mine), "precursor_difference": len(mine) - len(ref), "shear": shear,
            "length_mm": length * 1e3, "macro": macro, "front_speed": speed}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="full dynamics only at the largest time step")
    quick = parser.parse_args().quick
    listed = subprocess.run([BENCH, "--benchmark_list_tests"], check=True, capture_output=True, text=True).stdout
    # A case's name, or its name followed by its arguments ("chainStep/2" is not "chainStep/25").
    missing = [case for case in REQUIRED_CASES
               if not any(line == case or line.startswith(case + "/") for line in listed.split())]
    if missing:
        sys.exit("%s lacks %s: rebuild it (catkin_make ... bench_kernels)" % (BENCH, ", ".join(missing)))
    os.makedirs(OUT, exist_ok=True)
    reference = run("reference", {"integrator.time_step": "5e-8", "integrator.fast_forward": "false"})
    modes = []
    for scheme in ["velocity_verlet", "rk4"]:
        for dt in ["1e-7", "2e-7", "4e-7"] if scheme == "velocity_verlet" else ["2e-7", "4e-7"]:
            for ff in ["true", "false"]:
                if quick and ff == "false" and dt != "4e-7":
                    continue
                modes.append(("%s dt=%s ff=%s" % (scheme, dt, ff),
                              {"integrator.scheme": scheme, "integrator.time_step": dt, "integrator.fast_forward": ff}))
    modes.append(("velocity_verlet dt=2e-7 ff=true linearised",
                  {"integrator.time_step": "2e-7", "integrator.fast_forward": "true", "lattice.spring_form": "linearised"}))
    results = []
    for name, settings in modes:
        result = run(name.replace(" ", "_").replace("=", ""), settings)
        result["label"] = name
        result["errors"] = errors(result, reference)
        results.append(result)
        print(name, result["wall"], result["errors"], flush=True)
    lab_speed = {"stage.program": "[{mode: velocity, speed: 1.0e-5}]", "stop.time": 100}
    slow = run("slow_stage_ff_100s", dict(lab_speed, **{"integrator.fast_forward": "true"}))
    # About 8·10⁷ steps (10 minutes); skipped by --quick.
    slow_full = None if quick else run("slow_stage_full_100s", dict(lab_speed, **{"integrator.fast_forward": "false"}),
                                       timeout=3600)
    sizes = []
    for nx, nz in [(57, 31), (113, 61), (225, 121), (449, 241)]:
        if quick and nx > 113:
            continue
        dt = {57: "2e-7", 113: "1e-7", 225: "5e-8", 449: "2.5e-8"}[nx]
        settings = {"lattice.nodes_x": nx, "lattice.nodes_z": nz, "integrator.time_step": dt,
                    "integrator.fast_forward": "true"}
        # The default lattice is the default mode's run of the table above, not a second run of it (two
        # timings of one run read 19.7 and 20.7 ns per node-step in one report).
        name = "velocity_verlet_dt2e-7_fftrue" if (nx, nz) == (57, 31) else "size_%dx%d" % (nx, nz)
        result = run(name, settings, timeout=3600)
        sizes.append(result or {"settings": settings, "nodes": nx * nz, "timeout": 3600})
    # Five runs of every case, reported as their median and range: this shared machine's speed varies
    # by up to a third from one minute to the next, so the runs are spread over the minutes as five
    # passes over the cases rather than five repetitions in a row.
    bench_results = os.path.join(OUT, "bench_kernels.json")
    if os.path.exists(bench_results):
        with open(bench_results) as handle:
            bench = json.load(handle)
    else:
        bench = {"benchmarks": []}
        for _ in range(5):
            one_pass = subprocess.run([BENCH, "--benchmark_format=json", "--benchmark_min_time=0.5",
                                       "--benchmark_filter=latticeStep|naiveLatticeStep|chainStep|stateStream|"
                                       "leapfrogStream|bondDividerFloor"],
                                      check=True, capture_output=True, text=True).stdout
            bench["benchmarks"] += json.loads(one_pass)["benchmarks"]
        with open(bench_results, "w") as handle:
            json.dump(bench, handle)
    whole = [measured_run("default experiment (pmma_2d, first global event + 5 cycles)",
                          [SCENE, "--set", "stop.global_events=6"]),
             measured_run("10^6-node lattice (1401x751: pmma_2d at 0.1 mm spacing), loading + 100 steps",
                          [SCENE, "--set", "lattice.nodes_x=1401", "--set", "lattice.nodes_z=751",
                           "--set", "integrator.time_step=1e-8",
                           "--set", "integrator.fast_forward=false", "--set", "stop.time=1e-6"])]
    sensitivity = [measured_run("pmma_1d_side", [os.path.join(ROOT, "friction_sim/scenes/pmma_1d_side.yaml")]),
                   measured_run("pmma_1d_side, F_Z × (1 + 1e-12)",
                                [os.path.join(ROOT, "friction_sim/scenes/pmma_1d_side.yaml"),
                                 "--set", "load.normal_force=%.17g" % (1920.0 * (1 + 1e-12))])]
    write_report(reference, results, slow, slow_full, sizes, bench, whole, sensitivity)


def measured_run(label, args):
    """A fresh offline run in its own process: wall time, peak memory and its summary."""
    out = os.path.join(OUT, "measured", re.sub(r"[^A-Za-z0-9]+", "_", label))
    start = time.monotonic()
    # A small interpreter of its own runs the child, so that the peak memory is this run's alone. Not
    # os.wait4 from here: a child's peak counts its life before exec, a fork of this matplotlib-laden
    # process (58 MB, against 11 MB measured by /usr/bin/time for the default experiment).
    probe = ("import resource, subprocess, sys; subprocess.run(sys.argv[1:], check=True, "
             "stdout=subprocess.DEVNULL); print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    peak_kb = int(subprocess.run([sys.executable, "-c", probe, RUN] + args + ["--out", out], check=True,
                                 capture_output=True, text=True).stdout.split()[-1])
    wall = time.monotonic() - start
    with open(os.path.join(out, "summary.txt")) as handle:
        summary = handle.read()
    return {"label": label, "wall": wall, "peak_mb": peak_kb / 1024.0, "summary": summary}


def onset_error(result):
    """A mode's largest relative error of F_X at the precursors' onsets, floored at 1e-7 for the log axis."""
    return max(result["errors"]["shear"], 1e-7)


def pareto_front(results):
    """The modes that no other beats on both wall time and onset error, in order of wall time."""
    front = []
    for r in sorted(results, key=lambda r: (r["wall"], onset_error(r))):
        if not front or onset_error(r) < onset_error(front[-1]):
            front.append(r)
    return front


def default_mode(results):
    """The mode pmma_2d.yaml itself runs in: its integrator's scheme, time step and fast-forward."""
    with open(SCENE) as handle:
        integrator = yaml.safe_load(handle)["integrator"]
    for r in results:
        settings = r["settings"]
        if (settings.get("integrator.scheme", "velocity_verlet") == integrator["scheme"]
                and float(settings["integrator.time_step"]) == float(integrator["time_step"])
                and (settings["integrator.fast_forward"] == "true") == integrator["fast_forward"]
                and "lattice.spring_form" not in settings):
            return r
    raise RuntimeError("no mode runs as pmma_2d.yaml does")


def plot_pareto(results, default):
    """docs/figures/pareto.png: every mode's wall time against its largest onset-force error, the front of
    the modes no other beats on both, and the default. Colour says fast-forward or not, the marker the
    scheme (and spring form); each point is labelled with its dt alone, so that labels stay short."""
    fig, ax = plt.subplots(figsize=(8.5, 4.6))
    markers = {"velocity_verlet": "o", "rk4": "s", "linearised": "^"}
    kinds = set()
    ax.set_xscale("log")
    ax.set_yscale("log")
    # In decades: a label is about 0.2 wide and 0.05 high. A point with another that close on its right is
    # labelled on its left.
    position = {r["label"]: (math.log10(r["wall"]), math.log10(onset_error(r))) for r in results}
    for r in results:
        scheme = "linearised" if "linearised" in r["label"] else r["label"].split()[0]
        fast = "ff=true" in r["label"]
        kinds.add((scheme, fast))
        ax.scatter(r["wall"], onset_error(r), marker=markers[scheme], s=40, zorder=3,
                   color="tab:red" if fast else "tab:blue")
        dt_us = float(re.search(r"dt=([0-9.e-]+)", r["label"]).group(1)) * 1e6
        x, y = position[r["label"]]
        neighbour_right = any(0 < other_x - x < 0.2 and abs(other_y - y) < 0.05 for other_x, other_y in position.values())
        ax.annotate("%g µs" % dt_us, (r["wall"], onset_error(r)), xytext=(-6 if neighbour_right else 5, -4),
                    textcoords="offset points", ha="right" if neighbour_right else "left", fontsize=7, zorder=5,
                    bbox=dict(boxstyle="square,pad=0.1", facecolor="white", edgecolor="none", alpha=0.8))
        if r is default:
            ax.scatter(r["wall"], onset_error(r), marker="o", s=180, facecolors="none", edgecolors="black", zorder=4,
                       label="default (pmma_2d)")
    right_edge = 2 * max(r["wall"] for r in results)
    ax.set_xlim(right=right_edge)
    front = pareto_front(results)
    ax.step([r["wall"] for r in front] + [right_edge], [onset_error(r) for r in front] + [onset_error(front[-1])],
            where="post", color="grey", linewidth=1, linestyle="--", zorder=2, label="Pareto front")
    names = {"velocity_verlet": "velocity Verlet", "rk4": "RK4", "linearised": "velocity Verlet, linearised springs"}
    for scheme, fast in sorted(kinds):
        ax.scatter([], [], marker=markers[scheme], color="tab:red" if fast else "tab:blue",
                   label="%s, %s" % (names[scheme], "fast-forward" if fast else "full dynamics"))
    ax.set_xlabel("wall time to the first global event (s)")
    ax.set_ylabel("largest relative error of F_X at precursor onsets")
    ax.set_title("pmma_2d: speed against error (labels: time step)", fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ax.grid(True, which="major", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "docs/figures/pareto.png"), dpi=110)


def write_report(reference, results, slow, slow_full, sizes, bench, whole, sensitivity):
    default = default_mode(results)
    plot_pareto(results, default)
    lines = ["# Performance: speed against error", "",
             "Regenerated by `scripts/perf_report.py` (about 50 minutes on the machine below, 26 of them the "
             "full-dynamics run at 10 µm/s and 4 the 449 × 241 lattice, and 21 on a faster host of this kind; "
             "finished runs and the kernels' benchmark results in `.build/perf/` are reused, delete it to start "
             "afresh).", "",
             "Every change of speed is measured side by side against the build before it, in one sitting on one "
             "host, by `scripts/perf_side_by_side.py`: [the first section](#this-build-against-the-one-before-side-by-side).",
             "", side_by_side_section(), "",
             "## The machine", "",
             "- %s, %s; %d cores; every run on one thread but the threads table's" % (platform.processor() or platform.machine(),
                                                                           cpu_model(), os.cpu_count()),
             "- %s; g++ -O3 -march=native (option FRICTION_SIM_NATIVE)" % platform.platform(),
             "- measured on %s" % time.strftime("%Y-%m-%d"), ""]
    targets_at = len(lines)
    lines += [
             "## Kernels (Google Benchmark, `bench_kernels`)", "",
             "| case | ns per node-step (or block-step): median of 5 | fastest – slowest |", "|---|---|---|"]
    repetitions = {}
    for b in bench["benchmarks"]:
        if b.get("run_type") == "iteration":
            value = b.get("ns_per_node_step", b.get("ns_per_block_step"))
            repetitions.setdefault(b["run_name"], []).append(value * 1e9 if value < 1e-3 else value)
    median = {name: statistics.median(values) for name, values in repetitions.items()}
    for name, values in repetitions.items():
        lines.append("| %s | %.2f | %.2f – %.2f |" % (name, median[name], min(values), max(values)))
    lines[targets_at:targets_at] = targets_section(median, repetitions, whole)
    stream = repetitions.get("stateStream/1767", [math.nan])
    lines += ["", "The host is shared and its speed drifts from minute to minute, so the five passes are spread over "
              "the minutes rather than run in a row. `stateStream/1767`, a plain stream in cache whose cost no change "
              "to the project's code affects, ranged over %.2f – %.2f ns in them: compare a case with it rather than "
              "across regenerations." % (min(stream), max(stream)), ""] + kernels_discussion(median) + threads_section(median)
    lines += ["", "## Whole runs: wall time and peak memory", "",
              "Each in a fresh process; wall time includes building the model, the stability limit and the loading "
              "solve.", "", "| run | wall (s) | peak memory (MB) |", "|---|---|---|"]
    for w in whole:
        lines.append("| %s | %.2f | %.0f |" % (w["label"], w["wall"], w["peak_mb"]))
    lines += ["", "The 10⁶-node run's loading solve (2.1·10⁶ free degrees of freedom) "
              "uses conjugate gradients preconditioned by a geometric multigrid V-cycle (`GridMultigrid`: bilinear "
              "transfer, Galerkin coarse matrices, one Gauss–Seidel sweep each way, the direct factor on the coarsest "
              "level); lattices above 4·10⁵ free degrees of freedom use it, smaller ones the direct factor. Measured "
              "by hand (2026-11-21, with CHOLMOD's factor then): the direct factor has 2.4·10⁸ non-zeros at 10⁶ nodes "
              "(2.2 GB, whatever ordering CHOLMOD used) and the same run with it peaked at 2957 MB in 144 s; multigrid needs "
              "11–12 iterations to a 10⁻¹⁰ residual at 57 × 31, 113 × 61 and 225 × 121 alike (tested)."]
    reference_global = first_global(reference["events"])
    lines += ["", "## Every mode against the reference", "",
              "Scene `pmma_2d` to its first global event. Reference: velocity Verlet, dt = 50 ns, full dynamics "
              "(%.0f s, %d steps, %d precursors, µ_s,macro = %s)." % (
                  reference["wall"], reference["steps"], len(precursors(reference["events"])),
                  reference_global["peak_shear_ratio"] if reference_global else "none"), "",
              "| mode | wall (s) | steps | wall per node-step (ns) | precursors (Δ) | max ΔF_X/F_X at onsets | max ΔL_p (mm) | "
              "Δµ_s,macro | Δ front speed | energy residual |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        e = r["errors"]
        lines.append("| %s | %.2f | %d | %.1f | %d (%+d) | %.1e | %.2f | %.1e | %.1e | %.1e |" % (
            r["label"], r["wall"], r["steps"], r["wall"] / max(r["steps"], 1) / r["nodes"] * 1e9, e["precursors"],
            e["precursor_difference"], e["shear"], e["length_mm"], e["macro"], e["front_speed"], r["residual"]))
    best = min(results, key=lambda r: r["errors"]["shear"])
    fastest = min(results, key=lambda r: r["wall"])
    by_label = {r["label"]: r for r in results}
    # Fast-forward against full dynamics at the same scheme and dt.
    pairs = [(r, by_label[r["label"].replace("ff=true", "ff=false")]) for r in results
             if r["label"].endswith("ff=true") and r["label"].replace("ff=true", "ff=false") in by_label]
    cost = [full["wall"] / fast["wall"] for fast, full in pairs]
    accuracy = [onset_error(full) / onset_error(fast) for fast, full in pairs]
    lines += ["", "**Defaults.** `pmma_2d` uses %s (%.2f s; the fastest "
              "mode, %s, takes %.2f s), with the same precursors and arrest points as the reference, µ_s,macro "
              "within %.1e and onset forces within %.1e (the largest deviations are on the single-node events). "
              "The most accurate mode, %s (%.1e, %.2f s), is the choice when onset forces matter to better than a "
              "percent. At the same scheme and dt, full dynamics costs %.0f–%.0f× the wall time of fast-forward, "
              "and its onset-force error is %.2f–%.2f× fast-forward's." % (
                  default["label"], default["wall"], fastest["label"], fastest["wall"], default["errors"]["macro"],
                  default["errors"]["shear"], best["label"], best["errors"]["shear"], best["wall"], min(cost),
                  max(cost), min(accuracy), max(accuracy))]
    lines += ["", "With fast-forward the wall time per node-step includes the static solves of the jumps, so it is "
              "larger than the kernel's; the time to solution is what counts.", "",
              "![Pareto front](figures/pareto.png)", "",
              "On the Pareto front (no other mode both faster and more accurate at the precursors' onsets), from "
              "the fastest: %s." % ", ".join(r["label"] for r in pareto_front(results)), "",
              "## Fast-forward", "",
              "| stage speed | fast-forward: wall (s) | steps | full dynamics: wall (s) | steps | speed-up | "
              "first global event at (s), fast-forward / full |", "|---|---|---|---|---|---|---|"]
    full = next((r for r in results if r["label"] == "velocity_verlet dt=2e-7 ff=false"), None)

    def speed_row(speed, jumping, stepping):
        onset = lambda r: first_global(r["events"])["onset_time_s"] if r and first_global(r["events"]) else "none"
        if stepping is None:
            return "| %s | %.2f | %d | not run (--quick) or over an hour | – | – | %s / – |" % (speed, jumping["wall"], jumping["steps"], onset(jumping))
        return "| %s | %.2f | %d | %.1f | %d | %.0f× | %s / %s |" % (
            speed, jumping["wall"], jumping["steps"], stepping["wall"], stepping["steps"],
            stepping["wall"] / jumping["wall"], onset(jumping), onset(stepping))

    lines += [speed_row("0.4 mm/s", default, full), speed_row("10 µm/s", slow, slow_full), "",
              "Both with velocity Verlet at dt = 0.2 µs, to the first global event (at most 100 s simulated). At the "
              "lab's speed full dynamics needs 40× the steps, fast-forward about the same as at 0.4 mm/s."]
    lines += ["", "## Lattice size (fast-forward on, dt scaled with the spacing)", "",
              "| lattice | nodes | dt (s) | wall (s) | steps | wall per node-step (ns) | precursors |",
              "|---|---|---|---|---|---|---|"]
    for s in sizes:
        if "timeout" in s:
            lines.append("| %sx%s | %d | %s | not finished within %d s | – | – | – |" % (
                s["settings"]["lattice.nodes_x"], s["settings"]["lattice.nodes_z"], s["nodes"],
                s["settings"]["integrator.time_step"], s["timeout"]))
            continue
        lines.append("| %sx%s | %d | %s | %.2f | %d | %.1f | %d |" % (
            s["settings"]["lattice.nodes_x"], s["settings"]["lattice.nodes_z"], s["nodes"],
            s["settings"]["integrator.time_step"], s["wall"], s["steps"], s["wall"] / max(s["steps"], 1) / s["nodes"] * 1e9,
            len(precursors(s["events"]))))
    lines += ["", "The steps are those of the slip events; finer lattices find more single-node precursors, each a few "
              "dozen steps and a few jumps, and each jump is a static solve, so the wall time per node-step grows with "
              "the size. At 449 × 241 the trailing corner lifts off the track after some of them: fast-forward goes on "
              "with it free (the static solver is set up again for the new contact set) and stops where it would land. "
              "Before it did (2026-11-24), each lift-off kept the run in full dynamics until the next event ended: "
              "3815766 steps and 2170 s."]
    lines += ["", "## Round-off sensitivity of the 1D chain", "",
              "The same 1D scene with F_Z changed in the twelfth digit:", "",
              "| run | precursors before the first global event | µ_s,macro |", "|---|---|---|"]
    for r in sensitivity:
        count = re.search(r"precursors before the first global event: ([0-9]+)", r["summary"])
        macro = re.search(r"mu_s,macro = F_X/F_Z at the first global event: ([0-9.e+-]+)", r["summary"])
        lines.append("| %s | %s | %s |" % (r["label"], count.group(1) if count else "–", macro.group(1) if macro else "–"))
    lines += ["", "The early precursors are the same; late in the loading, where several blocks sit within round-off "
              "of their thresholds, the sequence of the chain's precursors (and its µ_s,macro) depends on the last "
              "bits of the arithmetic: a change of kernel that only changes round-off (such as multiplying by 1/m "
              "instead of dividing by m) changes it in the same way. Results of the chain beyond that point are "
              "statistical, not exact; the 2D lattice's default run is not sensitive in this way (the kernel "
              "rewrite left its events unchanged to the printed digits)."]
    open(REPORT, "w").write("\n".join(lines) + "\n")


def side_by_side_section(text=None):
    """The side-by-side section of the report (`text`, read if not given), markers included."""
    if text is None:
        text = open(REPORT).read() if os.path.exists(REPORT) else ""
    begin, end = text.find(SIDE_BY_SIDE[0]), text.find(SIDE_BY_SIDE[1])
    if begin < 0 or end < 0:
        return "%s\n(not measured yet: run scripts/perf_side_by_side.py)\n%s" % SIDE_BY_SIDE
    return text[begin:end + len(SIDE_BY_SIDE[1])]


def replace_side_by_side_section(section):
    """Writes `section` (without markers) into the report in place of the side-by-side section."""
    text = open(REPORT).read()
    old = side_by_side_section(text)
    if old not in text:
        sys.exit("%s has no side-by-side section: regenerate it with scripts/perf_report.py" % REPORT)
    open(REPORT, "w").write(text.replace(old, "%s\n%s\n%s" % (SIDE_BY_SIDE[0], section, SIDE_BY_SIDE[1])))


def targets_section(median, repetitions, whole):
    """Issue 5's speed and memory targets against this machine's measurements."""
    def kernel_cell(name):
        values = repetitions.get(name, [math.nan])
        return "%.2f ns (%.2f – %.2f)" % (median.get(name, math.nan), min(values), max(values))

    def verdict(value, met):
        """'not measured' if `value` is missing or not a number, else whether met(value)."""
        if value is None or math.isnan(value):
            return "not measured"
        return "met" if met(value) else "**not met** on this machine"

    sizes_median, distance = flatness(median, LATTICE_SIZES)
    _, distance_with_remainder = flatness(median, LATTICE_SIZES + [REMAINDER_SIZE])
    first, largest = ("latticeStep/geometric/" + size for size in (LATTICE_SIZES[0], LATTICE_SIZES[-1]))
    million_over_thousand = median.get(largest, math.nan) / median.get(first, math.nan)
    remainder = median.get("latticeStep/geometric/" + REMAINDER_SIZE, math.nan)
    if distance is None or distance_with_remainder is None:
        flat_verdict = "not measured"
    elif distance <= 0.2 and distance_with_remainder > 0.2:
        flat_verdict = "met on those sizes; **not met** with %s" % size_label(REMAINDER_SIZE)
    else:
        flat_verdict = verdict(distance, lambda d: d <= 0.2)
    experiment, million_nodes = whole
    rows = [
        ("2D step, 57 × 31, at most 5 ns per node-step",
         kernel_cell("latticeStep/geometric/57/31") + "; its square roots and divisions alone %.2f" % median.get(
             "bondDividerFloor", math.nan),
         verdict(median.get("latticeStep/geometric/57/31"), lambda ns: ns <= 5.0)),
        ("2D step flat from 10³ to 10⁶ nodes (taken as: every size within 20 % of the sizes' median; sizes "
         "whose runs of nx − 1 bonds are whole 8-wide vectors, as every lattice the scenes use, chosen on "
         "2026-11-25)",
         "furthest %.0f %% from the median; 10⁶ nodes %.2f× 10³ (%s). Not counted: %s, also 10³ nodes, "
         "%.2f ns, %.2f× the median (its runs of %d bonds leave %d over); counted with it, as the reports "
         "before 2026-11-25 did, the sizes lie up to %.0f %% from their median" % (
             100 * (distance if distance is not None else math.nan), million_over_thousand,
             size_label(LATTICE_SIZES[0]), size_label(REMAINDER_SIZE), remainder, remainder / sizes_median,
             run_length(REMAINDER_SIZE), left_over_bonds(REMAINDER_SIZE),
             100 * (distance_with_remainder if distance_with_remainder is not None else math.nan)),
         flat_verdict),
        ("1D chain, at most 2 ns per block-step (57 blocks, as pmma_1d_side)", kernel_cell("chainStep/57") +
         "; 10³ blocks %.2f, 10⁵ %.2f" % (median.get("chainStep/1000", math.nan), median.get("chainStep/100000", math.nan)),
         verdict(median.get("chainStep/57"), lambda ns: ns <= 2.0)),
        ("default experiment in at most 20 s, under 200 MB", "%.2f s, %.0f MB" % (experiment["wall"], experiment["peak_mb"]),
         verdict(experiment["wall"], lambda wall: wall <= 20.0 and experiment["peak_mb"] < 200.0)),
        ("10⁶-node lattice under 2 GB", "%.0f MB" % million_nodes["peak_mb"],
         verdict(million_nodes["peak_mb"], lambda mb: mb < 2048.0)),
    ]
    lines = ["## Targets (issue 5) on this machine", "",
             "| target | measured (kernels: median of 5 passes, fastest – slowest; whole runs: one run) | |",
             "|---|---|---|"]
    lines += ["| %s | %s | %s |" % row for row in rows]
    lines += ["", "The kernels' figures scale with the host's speed, which differs between machines of this kind and "
              "drifts on one: `stateStream/1767`, a plain in-cache stream, read %.2f ns here. Earlier "
              "regenerations on other hosts of this kind, all reported as \"AMD EPYC\": at commit de45b1a "
              "(2026-11-25) 0.38 ns for it, 4.30 ns for the 57 × 31 step and 1.98 ns for the chain; at commit "
              "2611929 (2026-11-25) 0.65, 5.93 and 2.53, neither target met." % median.get("stateStream/1767", math.nan), ""]
    return lines


# Changes to the kernels measured by hand and not kept, with a bound and a what-if that ruled changes out:
# (what was measured, the case and date, its cost, the cost without it on the same host and day, why it
# lost; a cell may be empty). The report prints these dated figures as given; it does not re-measure them.
TRIED_AND_DROPPED = [
    ("prefetching the next strip's rows into the L2 cache while the current rows' forces are computed",
     "10⁶ nodes, 2026-11-24, twice (interleaved A/B runs; the first pair fastest of 9)", "6.05 and 6.17",
     "5.34 and 5.64", ""),
    ("sweeping each row in chunks of 128 columns", "10⁶ nodes, 2026-11-24 (interleaved A/B runs)", "no change", "", ""),
    ("transparent huge pages for the state", "10⁶ nodes, 2026-11-24 (interleaved A/B runs)", "no change", "", ""),
    ("preparing the next rows in pieces between the current row's bond loops",
     "10⁶ nodes and 57 × 31, 2026-11-24 (interleaved A/B runs)", "7.08 and 5.00", "5.70 and 4.17", ""),
    ("the inverse square root from a bit-level first guess and four Newton steps, vectorised",
     "57 × 31, 2026-11-25", "6.85", "6.0",
     "the multiplies take the divider's place; two steps (5.88) fall short of double precision"),
    ("256-bit vectors (`-mprefer-vector-width=256`)", "57 × 31, 2026-11-25", "6.8", "6.0", ""),
    ("the square roots and divisions in a loop of their own over the row", "57 × 31, 2026-11-25", "12.4", "6.0", ""),
    ("1 − (1 + σ)^(−1/2), σ the squared stretch, as its power series to the eighth degree (exact to 2⁻⁵³ "
     "below |σ| = 0.01, the square root beyond)", "57 × 31, 2026-11-25", "7.9", "6.06",
     "sixteen multiplies and adds per bond, which this build does not fuse, cost more than the divider"),
    ("a run's left-over bonds as one whole vector", "32 × 32, 2026-11-25", "8.9–9.9", "8.0–8.3",
     "a lone vector's square root and division are waited for, where the loop's overlap"),
    ("a run's left-over bonds as one masked AVX-512 vector", "32 × 32 and 57 × 31, 2026-11-25", "9.0 and 6.9",
     "7.6 and 6.0",
     "a lone vector's square root and division are waited for"),
    ("one call per row for its four runs of bonds", "32 × 32, 2026-11-25", "7.6–8.2", "7.6–7.9", ""),
    ("two bonds' lengths inverted with one division (1/L₁ = L₂/(L₁L₂)), the horizontal with the diagonal and "
     "the vertical with the antidiagonal bonds", "57 × 31 and 449 × 241, 2026-11-25", "6.17–6.62 and 5.92–6.00",
     "5.87–6.03 and 6.09–6.34",
     "slower at the default size, 3–5 % faster at 449 × 241; results change in round-off (not byte for byte)"),
    ("a bound, not a change: the chain's viscous power not summed at all (the most that summing it inside the "
     "bond loop could save)", "chain, 57 blocks, 2026-11-25 (median of 5 interleaved runs, fastest – slowest)",
     "2.35 (2.26–2.49)", "2.46 (2.44–2.53)", "at most about 4 %; the chain's target needs 19 %"),
    ("link-time optimisation of the core (`-flto`), so that the step's small calls across source files inline",
     "chain at 2 and 57 blocks, 57 × 31, 2026-11-25 (median of 5 interleaved runs)",
     "68 ns a 2-block step; 2.49 at 57 blocks; 57 × 31 within 0.3 %", "73 ns; 2.44",
     "the fixed cost falls by 5 ns a step, the 57-block step does not"),
    ("what-if, a standalone program: the row's work as one software-pipelined loop (row j's bonds with the "
     "gathering and closing kick of row j − 1)", "57 × 31, 2026-11-25", "6.12", "6.60 (same work, separate loops)",
     "7 %: hiding the rest of the step under the divider would not reach 5 ns on that host"),
]


def threads_section(median):
    """The lattice's step on two threads against one, from the kernels' medians, as Markdown lines."""
    lines = ["", "### Threads", "",
             "Each step's sweep split into blocks of rows, one per thread (`--threads 2`); one step per sweep then. "
             "The results are the same to the last bit for any thread count (tests `LatticeThreads`, "
             "`SimulationThreads`).", "",
             "| lattice | one thread, steps in groups (ns per node-step) | two threads | speed-up |", "|---|---|---|---|"]
    for size in THREADED_SIZES:
        one, two = median["latticeStep/geometric/" + size], median[THREADED_CASE % size]
        lines.append("| %s | %.2f | %.2f | %.2f× |" % (size_label(size), one, two, one / two))
    return lines


def kernels_discussion(median):
    """The sections under the kernels' table, as Markdown lines: what the medians say about the lattice's
    cost over sizes, its divider, the chain's fixed cost, and what was tried and dropped (dated hand
    measurements)."""
    stream_small, stream_large = median["stateStream/1767"], median["stateStream/1002001"]
    lattice = {size: median["latticeStep/geometric/" + size] for size in LATTICE_SIZES}
    sizes_median, _ = flatness(median, LATTICE_SIZES)
    remainder = median["latticeStep/geometric/" + REMAINDER_SIZE]
    geometric, linearised = median["latticeStep/geometric/57/31"], median["latticeStep/linearised/57/31"]
    divider = median["bondDividerFloor"]
    unhidden = geometric - linearised  # the divider's time the step shows
    largest = lattice.pop("1001/1001")
    wide_rows = lattice.pop("1001/61")
    smaller = statistics.median(lattice.values())
    excess = largest - smaller
    memory_extra = stream_large - stream_small  # what a plain stream pays for memory over cache
    if wide_rows < 1.1 * smaller:
        row_width = ("The width of its rows is not the cause: a 1001 × 61 lattice, with the same rows and a state "
                     "that fits the last-level cache, costs %.2f ns." % wide_rows)
    else:
        row_width = ("A 1001 × 61 lattice, with the same rows and a state that fits the last-level cache, costs "
                     "%.2f ns: wide rows cost more too." % wide_rows)
    if excess > memory_extra:
        stalls = ("more than a plain stream pays for memory: memory stalls cost the step more than they cost a "
                  "stream, presumably because each strip is read in a burst before its forces are computed, with "
                  "little arithmetic left to hide it")
    else:
        stalls = "no more than a plain stream pays for memory"
    leapfrog_large = median["leapfrogStream/1002001"]
    chain_fixed_cost = 57 * (median["chainStep/57"] - median["chainStep/1000"])
    two_block_step = 2 * median["chainStep/2"]
    short_chain_step = 57 * median["chainStep/57"]
    across_sizes = [
        "The lattice's step is one sweep over the state: the model evaluates the forces in strips of about 4096 "
        "nodes (whole rows), and velocity Verlet's kick-and-drift and closing kick run on each strip while it is "
        "in the L2 cache (`StripHooks`). With separate passes a 10⁶-node step streamed its displacements, "
        "velocities and accelerations from memory five times and cost 6.6–9.4 ns per node-step. Now 10⁶ nodes "
        "cost %.2f ns, %.2f× the median of the smaller lattices, %s to %s (%.2f ns). %s" % (
            largest, largest / smaller, size_label(list(lattice)[0]), size_label(list(lattice)[-1]), smaller,
            row_width),
        "Velocity Verlet's traffic alone, each node's displacements, velocities and accelerations read and written "
        "once with a force that costs nothing (`stateStream`), costs %.2f ns per node at 10⁶ nodes (%.0f GB/s) "
        "and %.2f ns in cache: memory adds %.2f ns to a plain stream. The large lattice's step costs %.2f ns more "
        "than the smaller ones' median, %s. A sampling profile by hand on 2026-11-24 (`perf record -e "
        "cpu-clock`) puts the whole excess in the strips' preparation, velocity Verlet's kick-and-drift, the "
        "first pass to touch a strip: 1.64 ns per node at 10⁶ nodes against 0.76 ns at 1001 × 61, while the "
        "bond loops and the gathering of the forces cost the same in both. Measured by hand on 2026-11-24 with "
        "a standalone loop of the same 6-array stream, its cost per node is 0.45–0.5 ns while the arrays fit "
        "the L2 cache, about 0.67 ns up to 12 MB, 1.1 ns at 24 MB, 1.4 ns at 48 MB and 1.7 ns at 96 MB: every "
        "lattice up to 449 × 241 (under 6 MB of displacements, velocities and accelerations) streams from the "
        "last-level cache (about 32 MB on the host of that day), the 10⁶-node one (48 MB) from memory, the only "
        "one." % (
            stream_large, 96.0 / stream_large, stream_small, memory_extra, excess, stalls),
        "Storing half-step velocities in place of the accelerations (leapfrog) would stream 4 numbers per node "
        "instead of 6: `leapfrogStream` costs %.2f ns per node at 10⁶ nodes, %.2f× `stateStream` here, and "
        "0.75–1.0× in repeated runs by hand on 2026-11-24 (this host's speed drifts): at most about a quarter of "
        "the traffic's cost, for a change of integrator whose end-of-step velocities the friction rules read." % (
            leapfrog_large, leapfrog_large / stream_large),
        "Fewer passes over memory: where nothing at the interface changes from one step to the next (no node "
        "slides or starts to, no event is under way), up to three velocity Verlet steps are swept at once, each "
        "step's sweep one or two strips of about 2048 nodes behind the one before, so that a large state "
        "crosses the memory bus once for all of them, with the same results byte for byte "
        "(`Simulation::advance(until, group_before)`, which the offline runner uses between its loading-curve "
        "samples and the lattice cases above measure; the ROS node, whose instruments read the state on their "
        "own clocks, steps one at a time). Interleaved by hand in one process on 2026-11-24 (fastest of 15 "
        "rounds), the 10⁶-node lattice cost 5.38 ns per node-step one step at a time, 4.91 two at a time, "
        "4.70 three, 4.66 four, 4.88 six and 5.12 eight (strips of 1024 nodes for six and eight); four cost a "
        "1001 × 61 lattice 4 %% more than two (likely their row buffers, 100 kB a sweep at that width, crowding "
        "the L2 cache), three the same, and the smaller lattices cost the same in groups as one step at a time. "
        "One step at a time (`latticeStepOneAtATime`) the 10⁶-node lattice costs %.2f ns per node-step, and "
        "%.2f at 57 × 31. Grouping cuts the memory traffic of the held and loading phases, not the stall of the "
        "first pass over each strip: with three steps per sweep, kick-and-drift took 21 %% of the step's profile "
        "samples at 10⁶ nodes against 14 %% at 1001 × 61 (by hand, 2026-11-24)." % (
            median["latticeStepOneAtATime/1001/1001"], median["latticeStepOneAtATime/57/31"]),
        "The 10³-node lattices differ by their rows' width modulo 8: %s, whose runs of bonds are whole 8-wide "
        "vectors but for one bond, costs %.2f ns, and %s %.2f ns, %.2f× the median of the sizes in the targets "
        "table: by hand on 2026-11-25 (perf), its bond loops cost 40 %% more per node than 57 × 31's, GCC "
        "finishing each run of %d bonds with a 4-wide vector and three single bonds. Spread over a 1000-wide "
        "row, the same left-over bonds would add about 1 %%: the flatness target above is read on the sizes "
        "without them%s." % (
            size_label(LATTICE_SIZES[0]), median["latticeStep/geometric/" + LATTICE_SIZES[0]],
            size_label(REMAINDER_SIZE), remainder, remainder / sizes_median, run_length(REMAINDER_SIZE),
            ", and does not hold with %s" % size_label(REMAINDER_SIZE) if abs(remainder / sizes_median - 1) > 0.2
            else " (it holds with %s too on this host)" % size_label(REMAINDER_SIZE)),
    ]
    across_sizes.append(
        "For scale, a naive step of the same bulk (`naiveLatticeStep`, benchmarks/naive_lattice.h: each node "
        "sums its eight bonds, so every bond is computed twice; an array of node records; velocity Verlet's "
        "three passes each over the whole state; no contact rules, loads or pusher; its forces equal the "
        "model's to round-off, test `LatticeNaiveReference`) costs %s ns per node-step: the model's step, which "
        "does the contact rules and loads too, is %s as fast one step per sweep, as the naive one "
        "(`latticeStepOneAtATime`), and %s with its steps swept in groups (`latticeStep`)." % (
            ", ".join("%.2f at %s" % (median["naiveLatticeStep/" + size], size_label(size)) for size in NAIVE_SIZES),
            ", ".join("%.1f×" % (median["naiveLatticeStep/" + size] / median["latticeStepOneAtATime/" + size])
                      for size in NAIVE_SIZES),
            ", ".join("%.1f×" % (median["naiveLatticeStep/" + size] / median["latticeStep/geometric/" + size])
                      for size in NAIVE_SIZES)))
    divider_paragraph = (
        "Each geometric bond takes a square root and a division, neither instruction fully pipelined: the "
        "57 × 31 lattice's square roots and divisions alone, in a loop that does nothing else "
        "(`bondDividerFloor`), cost %.2f ns per node-step, %.0f %% of its %.2f ns step. Without them (the "
        "linearised springs) the step costs %.2f ns, so %.2f ns (%.0f %% of the step) of the divider's time is "
        "not hidden under the rest of the step%s; replacing the two operations by multiplies and adds costs "
        "as much or more ([below](#tried-by-hand-and-dropped))." % (
            divider, 100 * divider / geometric, geometric, linearised, unhidden, 100 * unhidden / geometric,
            ": reaching 5 ns here would need %.0f %% of that hidden" % (100 * (geometric - 5.0) / unhidden)
            if geometric > 5.0 and unhidden > 0 else ""))
    chain_paragraphs = [
        "The chain driven at its side (pmma_1d_side) is swept the same way: F_X, and with it every block's normal "
        "force, is known once block 0 is prepared, so each strip's friction is applied as soon as the strip is "
        "finished (driven from the top, F_X is a sum over every block and the chain keeps separate passes). "
        "At 10⁵ blocks, in the default scene held with every block stuck, it streams 7 arrays of one number per "
        "block once per step. It writes 6: displacements, velocities, forces turned accelerations, the normal "
        "forces, the friction and the other forces. It only reads each node's friction mode (stuck, sliding "
        "direction or detached). The normal-force profile (ξ, and 1 + θξ with tilt) is read only with tilt or "
        "the torque term, Amontons–Coulomb's µ_s and µ_k are read as two numbers, with rigid sticking the "
        "anchors are not read, and a sliding block adds its position, velocity and friction at the step's start.",
        "At 57 blocks a step costs %.0f ns more than 57 blocks' share of a 10³-block step, and a 2-block step "
        "costs %.0f ns: %.0f %% of a 57-block step (%.0f ns) is a fixed cost. Counted by hand with callgrind on "
        "2026-11-24 (in an AVX2 build: valgrind does not run AVX-512), after the trim below, that fixed cost is "
        "about 970 instructions per step spread over some fifteen functions: the force evaluation with the "
        "normal forces 28 %%, the integrator's passes and the strip plumbing 26 %%, the friction pass and its "
        "dispatch 15 %%, the contact's state bookkeeping 12 %%, the step's own logic 12 %%, the stage 5 %%, the "
        "event detector 3 %%. Sampled on 2026-11-25 with `perf record` at 57 blocks, the bond forces with the "
        "viscous power take 40 %% of the step, the friction pass 18 %%, velocity Verlet's kick-and-drift 9 %% "
        "and no other function over 6 %%." % (
            chain_fixed_cost, two_block_step, 100.0 * two_block_step / short_chain_step, short_chain_step),
        "Two of the step's loops were trimmed on 2026-11-24: the bond forces run without run-time alias checks, "
        "and without tilt or torque every normal force is F_Z/N, written without reading the profile or "
        "computing the torque term from F_X. By hand (interleaved with the build before, median of 21) that took "
        "a 57-block step from 2.03 to 1.86 ns per block-step, with the same results byte for byte.",
        "Built for CPUs with AVX2 but not AVX-512 (`scripts/build.sh -DFRICTION_SIM_NATIVE=OFF "
        "-DCMAKE_CXX_FLAGS=-march=x86-64-v3`), measured by hand on 2026-11-24 on the faster host of commit "
        "de45b1a's report (interleaved, median of 21), where the native build read 4.30 ns at 57 × 31: "
        "1.37 ns per block-step at 10³ blocks, 2.11 at 57, and 5.45 ns per node-step at 57 × 31.",
    ]
    lines = ["### The lattice across sizes", ""]
    for paragraph in across_sizes:
        lines += [paragraph, ""]
    lines += ["### The lattice at 57 × 31: the divider", "", divider_paragraph, "", "### The chain", ""]
    for paragraph in chain_paragraphs:
        lines += [paragraph, ""]
    lines += ["### Tried by hand and dropped", "",
              "ns per node-step (per block-step for the chain); each change against the code without it, on the same "
              "host and day. None is in the code.", "",
              "| change | case, date | with it | without | why it lost |", "|---|---|---|---|---|"]
    lines += ["| %s |" % " | ".join(cell.replace("|", "\\|") for cell in row) for row in TRIED_AND_DROPPED]
    return lines


def cpu_model():
    """The CPU's name with its family and model numbers: hosts of this kind all call themselves "AMD EPYC",
    and their generations differ in speed by up to half."""
    fields = {}
    for line in open("/proc/cpuinfo"):
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    return "%s (family %s, model %s; L2 %s per core)" % (fields.get("model name", "unknown CPU"),
                                                          fields.get("cpu family", "?"), fields.get("model", "?"),
                                                          fields.get("cache size", "?"))


if __name__ == "__main__":
    main()
