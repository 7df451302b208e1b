#!/usr/bin/python3
"""Measures this build against an earlier one, interleaved in one sitting on one host, and writes the
first section of docs/PERFORMANCE.md: every case as a ratio, the cost of whole runs against the number of
nodes (its exponent), the share of dynamic stepping and of start-up in each, and the threads' gain.

    scripts/perf_side_by_side.py BASE_REV [--rounds N] [--rewrite]

Builds BASE_REV's friction_run in a worktree (.build/baseline/<rev>), then runs each case with both
runners, round after round, the two in a random order within each case, so that the host's drift falls on
both alike. Runs are fresh processes; a case's time is the process's wall time. The measurements are
kept in .build/baseline/side_by_side.json: --rewrite writes the report from them again without running.
About 3.5 minutes a round on a 2-core AMD EPYC of family 25 (2026-11-27), most of it the 225 × 121 and
449 × 241 runs.
"""
import argparse
import csv
import json
import math
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from perf_report import REPORT, SCENE, cpu_model, replace_side_by_side_section  # noqa: E402
from sweep import ROOT, RUNNER  # noqa: E402

MEASURED = os.path.join(ROOT, ".build/baseline/side_by_side.json")
# The lattices of the report (nodes_x, nodes_z, dt): pmma_2d's slider, dt scaled with the spacing.
SIZES = [(57, 31, "2e-7"), (113, 61, "1e-7"), (225, 121, "5e-8"), (449, 241, "2.5e-8")]
# A size's cost per node-step in a run: the difference of two full-dynamics runs of STEPPED and
# STEPPED + EXTRA steps, over EXTRA steps, so that everything but the steps cancels. EXTRA is long
# enough for its steps to stand out of the start-up's noise (449 × 241 starts up in about 5 s).
STEPPED = 2000
EXTRA = 10000
# The sizes whose whole run to the first global event is measured: 449 × 241's takes minutes a run.
WHOLE_RUN_SIZES = 3
# Runs per round of a start-up case: the small ones take milliseconds, and the host's noise is as large.
STARTUP_REPEATS = 7
# The name of a start-up case (a run that stops at once) begins with this.
STARTUP = "start-up "
# A process that loads friction_run's libraries, prints its help and exits: the time before `main`,
# bounded from above (it also holds the help's printing and the exit).
PROGRAM_LOAD = "program load (friction_run --help)"


def short_commit(rev):
    return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", rev], check=True, capture_output=True,
                          text=True).stdout.strip()


def build_baseline(rev):
    """The friction_run of `rev`, built in its own worktree and catkin workspace."""
    commit = short_commit(rev)
    tree = os.path.join(ROOT, ".build/baseline", commit)
    if not os.path.isdir(tree):
        subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", tree, commit], check=True)
    runner = os.path.join(tree, ".build/devel/lib/friction_sim/friction_run")
    if not os.path.exists(runner):
        env = dict(os.environ, PATH="/usr/bin:" + os.environ["PATH"])
        subprocess.run([os.path.join(tree, "scripts/build.sh"), "-j2", "friction_run"], check=True, env=env,
                       stdout=subprocess.DEVNULL)
    return commit, runner


def stepped_name(steps, nx, nz, threads=1):
    return "%d steps %d × %d%s" % (steps, nx, nz, ", %d threads" % threads if threads > 1 else "")


def cases():
    """(name, settings, threads): start-up, stepping and whole runs at each size, and threads."""
    listed = [(PROGRAM_LOAD, None, 1)]
    for index, (nx, nz, dt) in enumerate(SIZES):
        size = {"lattice.nodes_x": nx, "lattice.nodes_z": nz, "integrator.time_step": dt}
        label = "%d × %d" % (nx, nz)
        listed.append((STARTUP + label, dict(size, **{"stop.time": "1e-9"}), 1))
        for steps in (STEPPED, STEPPED + EXTRA):
            full = dict(size, **{"integrator.fast_forward": "false", "stop.time": "%g" % ((steps - 0.5) * float(dt))})
            listed.append((stepped_name(steps, nx, nz), full, 1))
            if index == len(SIZES) - 1:
                listed.append((stepped_name(steps, nx, nz, 2), full, 2))
        if index < WHOLE_RUN_SIZES:
            listed.append(("first global event " + label, size, 1))
    return listed


def per_node_step(medians, build, nx, nz, threads=1):
    """s per node-step of a build's full-dynamics steps, from the two stepped runs' medians."""
    longer = medians[stepped_name(STEPPED + EXTRA, nx, nz, threads)][build]
    shorter = medians[stepped_name(STEPPED, nx, nz, threads)][build]
    return (longer - shorter) / (EXTRA * nx * nz)


def timed_run(runner, settings, threads, out):
    """Wall time (s) of one run in a fresh process, its step count, its events' onsets and kinds, and the
    wall time from `main` to its first step (None where the build does not print it). With no settings,
    the process only prints friction_run's help."""
    if settings is None:
        start = time.monotonic()
        subprocess.run([runner, "--help"], check=True, stdout=subprocess.DEVNULL)
        return time.monotonic() - start, 0, [], None
    args = [runner, SCENE, "--out", out]
    for key, value in settings.items():
        args += ["--set", "%s=%s" % (key, value)]
    if threads > 1:
        args += ["--threads", str(threads)]
    start = time.monotonic()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.monotonic() - start
    with open(os.path.join(out, "summary.txt")) as handle:
        summary = handle.read()
    steps = int(re.search(r"in ([0-9]+) steps", summary).group(1))
    before_first_step = re.search(r"before the first step ([0-9.e+-]+) s", summary)
    with open(os.path.join(out, "events.csv")) as handle:
        events = [(row["onset_time_s"], row["global"]) for row in csv.DictReader(handle)]
    return wall, steps, events, float(before_first_step.group(1)) if before_first_step else None


def measure(builds, rounds):
    """{case name: {build: [wall per round]}}, steps and events per case and build, and {case name: {build:
    [s from `main` to the first step]}} for the builds that print it."""
    walls, steps, events, first_steps = {}, {}, {}, {}
    work = tempfile.mkdtemp(prefix="side_by_side_")
    for round_index in range(rounds):
        for name, settings, threads in cases():
            order = [b for b in builds if threads == 1 or b == "this build"]
            random.shuffle(order)
            for _ in range(STARTUP_REPEATS if name.startswith(STARTUP) or name == PROGRAM_LOAD else 1):
                for build in order:
                    out = os.path.join(work, build.replace(" ", "_"))
                    wall, count, onsets, before_first_step = timed_run(builds[build], settings, threads, out)
                    walls.setdefault(name, {}).setdefault(build, []).append(wall)
                    if before_first_step is not None:
                        first_steps.setdefault(name, {}).setdefault(build, []).append(before_first_step)
                    steps[(name, build)] = count
                    events[(name, build)] = onsets
                    print("round %d  %-40s %-12s %8.3f s" % (round_index + 1, name, build, wall), flush=True)
    return walls, steps, events, first_steps


def spread(values):
    return "%.3f (%.3f – %.3f)" % (statistics.median(values), min(values), max(values))


def exponent(points):
    """The slope of log(wall) against log(nodes), least squares."""
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(w) for _, w in points]
    mx, my = statistics.mean(xs), statistics.mean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def agreement(name, steps, events):
    """How the two builds' runs of a case agree: "same", the onsets' largest relative difference where
    only those moved, or what differs."""
    base, this = events[(name, "base")], events[(name, "this build")]
    if steps[(name, "base")] != steps[(name, "this build")]:
        return "no: %d against %d steps" % (steps[(name, "this build")], steps[(name, "base")])
    if [kind for _, kind in base] != [kind for _, kind in this]:
        return "no: %d against %d events" % (len(this), len(base))
    moved = max([abs(float(a) / float(b) - 1.0) for (a, _), (b, _) in zip(this, base)] + [0.0])
    return "same" if moved == 0.0 else "same, onsets within %.0e" % moved


def write(base, head, walls, steps, events, first_steps, rounds, startup_repeats):
    builds = ["base", "this build"]
    lines = ["## This build against the one before, side by side", "",
             "The one before: %s." % base,
             "Regenerated by `scripts/perf_side_by_side.py %s --rounds %d` at %s on %s, %s (%d cores), "
             "%s. Each case ran once per round with each build (a start-up and the program load %d times), the "
             "two in a random order; "
             "wall times of fresh processes, medians of %d rounds (fastest – slowest). Speed-up: the base's "
             "median over this build's." % (base, rounds, head, cpu_model(), os.uname().machine, os.cpu_count(),
                                            time.strftime("%Y-%m-%d"), startup_repeats, rounds), "",
             "| case | %s (s) | this build (s) | speed-up | steps and events |" % base, "|---|---|---|---|---|"]
    medians = {name: {b: statistics.median(v) for b, v in per_build.items()} for name, per_build in walls.items()}
    for name, _, threads in cases():
        if threads > 1 or name not in walls:  # measurements kept from before a case was added lack it
            continue
        lines.append("| %s | %s | %s | %.2f× | %s |" % (name, spread(walls[name]["base"]),
                                                         spread(walls[name]["this build"]),
                                                         medians[name]["base"] / medians[name]["this build"],
                                                         "" if name == PROGRAM_LOAD else
                                                         agreement(name, steps, events)))
    lines += ["", "### Where a whole run's time goes", "",
              "Per node-step: the difference of the %d- and %d-step full-dynamics runs over %d steps × nodes. "
              "Dynamic share: the whole run's steps × nodes at that cost, over its wall time. Start-up share: the "
              "start-up's wall time (a run that stops at once: building, checking and loading the slider, "
              "fast-forward's set-up, and also writing its results and exiting) over the whole run's. Before the "
              "first step: the program's load (a `friction_run --help` process) and the whole run's own time from "
              "`main` to its first step (its summary's), over its wall time; a build that does not print it has "
              "none." % (STEPPED, STEPPED + EXTRA, EXTRA), "",
              "| lattice | build | whole run (s) | steps | ns per node-step | dynamic share | start-up share | "
              "before the first step |", "|---|---|---|---|---|---|---|---|"]
    points = {b: [] for b in builds}
    for nx, nz, _ in SIZES[:WHOLE_RUN_SIZES]:
        label, nodes = "%d × %d" % (nx, nz), nx * nz
        for build in builds:
            whole = medians["first global event " + label][build]
            startup = medians[STARTUP + label][build]
            cost = per_node_step(medians, build, nx, nz)
            run_steps = steps[("first global event " + label, build)]
            points[build].append((nodes, whole))
            own = first_steps.get("first global event " + label, {}).get(build)
            before = ("%.1f %%" % (100 * (medians[PROGRAM_LOAD][build] + statistics.median(own)) / whole)
                      if own else "–")
            lines.append("| %s | %s | %.2f | %d | %.1f | %.0f %% | %.0f %% | %s |" % (
                label, base if build == "base" else build, whole, run_steps, cost * 1e9,
                100 * run_steps * nodes * cost / whole, 100 * startup / whole, before))
    lines += ["", "Whole runs grow as N^%.2f with this build and N^%.2f with %s (least squares over %s nodes)." % (
        exponent(points["this build"]), exponent(points["base"]), base,
        ", ".join(str(nx * nz) for nx, nz, _ in SIZES[:WHOLE_RUN_SIZES]))]
    nx, nz, _ = SIZES[-1]
    one, two = (per_node_step(medians, "this build", nx, nz, threads) for threads in (1, 2))
    same = all((steps[(stepped_name(n, nx, nz), "this build")], events[(stepped_name(n, nx, nz), "this build")]) ==
               (steps[(stepped_name(n, nx, nz, 2), "this build")], events[(stepped_name(n, nx, nz, 2), "this build")])
               for n in (STEPPED, STEPPED + EXTRA))
    lines += ["", "### Threads", "",
              "| %d × %d, full dynamics | 1 thread (ns per node-step) | 2 threads | speed-up | same steps and events |"
              % (nx, nz), "|---|---|---|---|---|",
              "| this build | %.1f | %.1f | %.2f× | %s |" % (one * 1e9, two * 1e9, one / two, "yes" if same else "no")]
    replace_side_by_side_section("\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", help="the earlier build's git revision")
    parser.add_argument("--rounds", type=int, default=3, help="rounds of the interleaved runs (default 3)")
    parser.add_argument("--rewrite", action="store_true", help="write the report from the kept measurements")
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error("--rounds: value %d is not allowed; allowed: an integer >= 1" % args.rounds)
    if args.rewrite:
        with open(MEASURED) as handle:
            kept = json.load(handle)
        steps = {tuple(key.split("|")): value for key, value in kept["steps"].items()}
        events = {tuple(key.split("|")): [tuple(e) for e in value] for key, value in kept["events"].items()}
        write(kept["base"], kept.get("head", "?"), kept["walls"], steps, events, kept.get("first_steps", {}),
              kept["rounds"], kept.get("startup_repeats", 1))
        return
    head = short_commit("HEAD")
    commit, base_runner = build_baseline(args.base)
    walls, steps, events, first_steps = measure({"base": base_runner, "this build": RUNNER}, args.rounds)
    with open(MEASURED, "w") as handle:
        json.dump({"base": commit, "head": head, "rounds": args.rounds, "startup_repeats": STARTUP_REPEATS,
                   "walls": walls, "first_steps": first_steps,
                   "steps": {"|".join(key): value for key, value in steps.items()},
                   "events": {"|".join(key): value for key, value in events.items()}}, handle)
    write(commit, head, walls, steps, events, first_steps, args.rounds, STARTUP_REPEATS)
    print("written", REPORT)


if __name__ == "__main__":
    main()
