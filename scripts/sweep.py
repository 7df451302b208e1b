#!/usr/bin/python3
"""sweep: runs every combination of scene parameters and collects the event tables.

    scripts/sweep.py SWEEP.yaml [--jobs N] [--hosts SSHLOGINS] [--out DIR]

SWEEP.yaml names a base scene, fixed overrides and the parameters to vary:

    base: friction_sim/scenes/pmma_2d.yaml       # relative to the repository
    protocol: friction_sim/protocols/stop_and_go.yaml  # optional: every run follows it (--protocol)
    set: {stop.global_events: 1}                  # applied to every run
    vary:                                         # every combination runs
      load.normal_force: [1000, 1920, 4000]
      pusher.height: [0.0, 0.005]
    cases:                                        # optional: parameters that change together
      - {lattice.nodes_x: 57, lattice.nodes_z: 31}
      - {lattice.nodes_x: 113, lattice.nodes_z: 61}

Each run is an independent friction_run process, written down in its directory as command.sh.
GNU parallel spreads the runs over the local cores (--jobs, default all) and, with --hosts
(parallel's --sshlogin list, e.g. "2/node1,2/node2,:" where ":" is this machine), over other
machines reached by ssh (parallel's PARALLEL_SSH environment variable names another ssh command).
Those machines need this repository built at the same path and rsync; they need not share a file
system: parallel copies each run's command.sh there and brings its directory back with rsync. A
rerun skips the runs that finished (they wrote their summary.txt), also after values were added to the
sweep, and retries the others; DIR/joblog.txt keeps every attempt. A failed run is reported and the
others' results are kept. The runs' event tables are collected into
DIR/events.csv with one column per varied parameter (DIR defaults to sweeps/<sweep file name>).
"""
import argparse
import collections
import csv
import itertools
import os
import shlex
import subprocess
import sys

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNNER = os.path.join(ROOT, ".build/devel/lib/friction_sim/friction_run")


def load(path):
    try:
        with open(path) as handle:
            spec = yaml.safe_load(handle)
    except (OSError, yaml.YAMLError) as error:
        sys.exit("sweep: %s cannot be read: %s" % (path, error))
    if not isinstance(spec, dict):
        sys.exit("sweep: %s: expected a mapping with base (required), protocol, set, vary, cases" % path)
    unknown = set(spec) - {"base", "protocol", "set", "vary", "cases"}
    if unknown or "base" not in spec:
        sys.exit("sweep: %s: keys allowed are base (required), protocol, set, vary, cases; got %s" % (
            path, sorted(spec)))
    problems = ["%s: expected a path, got %r" % (key, spec[key]) for key in ("base", "protocol")
                if key in spec and not isinstance(spec[key], str)]
    if not isinstance(spec.get("set") or {}, dict):
        problems.append("set: expected a mapping of scene fields to values, got %r" % spec["set"])
    vary = spec.get("vary") or {}
    if not isinstance(vary, dict):
        problems.append("vary: expected a mapping of scene fields to lists of values, got %r" % vary)
    else:
        # A bare value would fail later; a string would be varied letter by letter.
        problems += ["vary.%s: expected a non-empty list of values, got %r" % (name, values)
                     for name, values in vary.items() if not isinstance(values, list) or not values]
    cases = spec.get("cases") or []
    if not isinstance(cases, list) or not all(isinstance(case, dict) for case in cases):
        problems.append("cases: expected a list of mappings of scene fields to values, got %r" % cases)
    if problems:
        sys.exit("sweep: %s:\n  %s" % (path, "\n  ".join(problems)))
    return spec


def combinations(spec):
    names = list((spec.get("vary") or {}).keys())
    values = [spec["vary"][name] for name in names]
    for case in spec.get("cases") or [{}]:
        for combo in itertools.product(*values):
            yield dict(case, **dict(zip(names, combo)))


def run_id(point):
    def short(value):
        text = str(value)
        return "".join(c for c in text if c.isalnum() or c in ".-e")[:40]
    return "_".join("%s=%s" % (name.split(".")[-1], short(value)) for name, value in point.items()) or "base"


def command(spec, point, out_dir):
    """The shell command of one run: friction_run with the sweep's overrides, its output logged."""
    args = [RUNNER, os.path.join(ROOT, spec["base"]), "--out", out_dir]
    if "protocol" in spec:
        args += ["--protocol", os.path.join(ROOT, spec["protocol"])]
    for name, value in list((spec.get("set") or {}).items()) + list(point.items()):
        # Strings are YAML already (e.g. a stage program); numbers and booleans are written as YAML.
        text = value if isinstance(value, str) else yaml.safe_dump(value, default_flow_style=True)
        args += ["--set", "%s=%s" % (name, text.strip().removesuffix("...").strip())]
    return " ".join(shlex.quote(a) for a in args) + " > " + shlex.quote(os.path.join(out_dir, "log.txt")) + " 2>&1"


def run(path, jobs=None, hosts=None, out=None):
    spec = load(path)
    out = out or os.path.join(ROOT, "sweeps", os.path.splitext(os.path.basename(path))[0])
    points = list(combinations(spec))
    ids = [run_id(point) for point in points]
    shared = sorted(i for i, count in collections.Counter(ids).items() if count > 1)
    if shared:
        # Their runs would write one directory, each over the other's results.
        sys.exit("sweep: %s: runs that differ only in what their directory names leave out share %s; "
                 "shorten the values or vary fewer fields of one name" % (path, ", ".join(shared)))
    run_dirs = []
    for point, point_id in zip(points, ids):
        run_dir = os.path.join(out, "runs", point_id)
        os.makedirs(run_dir, exist_ok=True)
        with open(os.path.join(run_dir, "command.sh"), "w") as handle:
            handle.write("#!/bin/sh\nexec %s\n" % command(spec, point, run_dir))
        run_dirs.append(run_dir)
    # A run is done once it has written its summary: only the others go to parallel (its own resume goes
    # by the jobs' order, which a value added to the sweep shifts). Its job log keeps every attempt.
    to_run = [d for d in run_dirs if not os.path.exists(os.path.join(d, "summary.txt"))]
    if not to_run:
        return collect(spec, points, out)
    args = ["parallel", "--joblog", "+" + os.path.join(out, "joblog.txt"), "--halt", "never"]
    if jobs:
        args += ["--jobs", str(jobs)]
    if hosts:
        # Absolute paths: rsync puts command.sh at the same path there and the run's directory back here.
        # A run whose host fails (its ssh connection drops) is retried on another host.
        args += ["--sshlogin", hosts, "--transferfile", "{}/command.sh", "--return", "{}", "--retries", "3"]
    # parallel quotes the paths it hands rsync for the remote shell; rsync 3.2.4 and later would quote
    # them again (a run named "normal_force=1000" comes back as "'./normal_force=1000'") unless told
    # to pass them as they are.
    environment = dict(os.environ, RSYNC_OLD_ARGS="1")
    subprocess.run(args + ["sh {}/command.sh"], input="\n".join(to_run) + "\n", text=True, env=environment)
    return collect(spec, points, out)


def precursors(events):
    """The events of one run's table before its first global slip event, back-slips (mean slip against x)
    left out as friction_run's summary leaves them out."""
    out = []
    for event in events:
        if event["global"] == "1":
            break
        if not float(event.get("mean_slip_m") or "nan") < 0.0:  # a run without the column slid forward
            out.append(event)
    return out


def extended_precursors(events):
    """A run's precursors with an extent, L_p > 0 (single-node slips left out)."""
    return [event for event in precursors(events) if float(event["rupture_length_m"]) > 0]


def first_global(events):
    """The first global slip event of one run's table, or None."""
    return next((event for event in events if event["global"] == "1"), None)


def failure_reason(log, lines=12):
    """The end of a failed run's log, where friction_run says why (a refused scene lists its problems)."""
    try:
        with open(log) as handle:
            tail = handle.read().strip().splitlines()[-lines:]
    except OSError:
        return "  (no log: the run did not start)"
    return "\n".join("  " + line for line in tail)


def collect(spec, points, out):
    rows, failed = [], []
    for point in points:
        run_dir = os.path.join(out, "runs", run_id(point))
        events = os.path.join(run_dir, "events.csv")
        if not os.path.exists(os.path.join(run_dir, "summary.txt")):
            failed.append(run_id(point))
            continue
        with open(events) as handle:
            for row in csv.DictReader(handle):
                rows.append(dict(point, run=run_id(point), **row))
    if rows:
        # Every column of every run: a run kept from an older friction_run may lack the newer ones (nan there).
        columns = list(dict.fromkeys(key for row in rows for key in row))
        with open(os.path.join(out, "events.csv"), "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=columns, restval="nan")
            writer.writeheader()
            writer.writerows(rows)
    for name in failed:
        log = os.path.join(out, "runs", name, "log.txt")
        print("sweep: run %s failed (%s):\n%s" % (name, log, failure_reason(log)), file=sys.stderr)
    print("sweep: %d of %d runs done, %d events in %s" % (len(points) - len(failed), len(points), len(rows),
                                                           os.path.join(out, "events.csv")))
    return rows, failed


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sweep", help="the sweep's YAML file (base, set, vary, cases)")
    parser.add_argument("--jobs", default=None, help="runs at once on each machine (default: one per core)")
    parser.add_argument("--hosts", default=None,
                        help="GNU parallel's --sshlogin list, e.g. '2/node1,2/node2,:' (':' is this machine)")
    parser.add_argument("--out", default=None, help="results folder (default: sweeps/<sweep file name>)")
    args = parser.parse_args()
    rows, failed = run(args.sweep, args.jobs, args.hosts, args.out)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
