#!/usr/bin/python3
"""The sweep tool (scripts/sweep.py) on the single-block scene, whose onset force is µ_s·F_Z exactly:
every combination runs, a refused run is reported without losing the others, a rerun skips what is
done, and runs spread over "remote" machines through GNU parallel's --sshlogin (with an ssh stand-in
that runs the command here, so that no ssh server is needed)."""
import csv
import os
import shutil
import sys
import tempfile
import unittest
from unittest import mock

import rosunit
import yaml
from catkin.find_in_workspaces import find_in_workspaces

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import sweep  # noqa: E402

with open(os.path.join(ROOT, "friction_sim/scenes/single_block.yaml")) as scene:
    STATIC_COEFFICIENT = yaml.safe_load(scene)["friction"]["static_coefficient"]


class SweepTest(unittest.TestCase):
    def setUp(self):
        runners = find_in_workspaces(["libexec"], project="friction_sim", path="friction_run", first_match_only=True)
        self.assertTrue(runners, "friction_run is not built")
        runner = mock.patch.object(sweep, "RUNNER", runners[0])
        runner.start()
        self.addCleanup(runner.stop)
        self.work = tempfile.mkdtemp(prefix="sweep_test_")
        self.addCleanup(shutil.rmtree, self.work)

    def write_sweep(self, normal_forces):
        path = os.path.join(self.work, "forces.yaml")
        with open(path, "w") as handle:
            handle.write("base: friction_sim/scenes/single_block.yaml\n"
                         "set: {stop.global_events: 2}\n"
                         "vary: {load.normal_force: %s}\n" % normal_forces)
        return path

    def assert_onsets_follow_amontons(self, rows, normal_forces):
        by_force = {}
        for row in rows:
            by_force.setdefault(float(row["load.normal_force"]), []).append(row)
        self.assertEqual(sorted(by_force), sorted(normal_forces))
        for normal_force, events in by_force.items():
            self.assertEqual(len(events), 2)
            for event in events:
                self.assertAlmostEqual(float(event["onset_shear_force_N"]), STATIC_COEFFICIENT * normal_force,
                                       delta=1e-9 * normal_force)

    def test_a_refused_run_is_reported_and_the_others_are_kept(self):
        out = os.path.join(self.work, "out")
        rows, failed = sweep.run(self.write_sweep("[1000, 2000, -5]"), jobs=2, out=out)
        self.assertEqual(failed, ["normal_force=-5"])
        self.assert_onsets_follow_amontons(rows, [1000.0, 2000.0])
        with open(os.path.join(out, "events.csv")) as handle:
            self.assertEqual(len(list(csv.DictReader(handle))), 4)
        with open(os.path.join(out, "runs", "normal_force=-5", "log.txt")) as handle:
            self.assertIn("normal_force", handle.read())

    def test_a_rerun_skips_finished_runs_and_retries_failed_ones(self):
        out = os.path.join(self.work, "out")
        path = self.write_sweep("[1000, -5]")
        sweep.run(path, jobs=1, out=out)
        summary = os.path.join(out, "runs", "normal_force=1000", "summary.txt")
        first_finish = os.stat(summary).st_mtime_ns
        rows, failed = sweep.run(path, jobs=1, out=out)
        self.assertEqual(os.stat(summary).st_mtime_ns, first_finish)
        self.assertEqual(failed, ["normal_force=-5"])
        self.assert_onsets_follow_amontons(rows, [1000.0])
        with open(os.path.join(out, "joblog.txt")) as handle:
            commands = [line.split("\t")[-1] for line in handle.read().splitlines()[1:]]
        self.assertEqual(sum("normal_force=1000" in c for c in commands), 1)
        self.assertEqual(sum("normal_force=-5" in c for c in commands), 2)

    def test_runs_spread_over_remote_hosts(self):
        calls = os.path.join(self.work, "ssh_calls.txt")
        stand_in = os.path.join(self.work, "ssh")
        with open(stand_in, "w") as handle:
            # parallel calls `ssh HOST -- COMMAND...`, the command meant for the remote shell. sshd sets
            # SHELL, which parallel's remote side runs the job with (without it the job silently does
            # nothing and exits 0; CI runs the tests without SHELL).
            handle.write('#!/bin/sh\necho "$1" >> %s\nshift\n[ "$1" = "--" ] && shift\n'
                         'SHELL=/bin/sh; export SHELL\nexec /bin/sh -c "$*"\n' % calls)
        # Through /bin/sh, so that a temporary directory mounted noexec does not matter.
        with mock.patch.dict(os.environ, PARALLEL_SSH="/bin/sh " + stand_in):
            rows, failed = sweep.run(self.write_sweep("[1000, 2000, 3000, 4000]"), hosts="1/node1,1/node2",
                                     out=os.path.join(self.work, "out"))
        self.assertEqual(failed, [])
        self.assert_onsets_follow_amontons(rows, [1000.0, 2000.0, 3000.0, 4000.0])
        with open(calls) as handle:
            hosts = set(handle.read().split())
        self.assertEqual(hosts, {"node1", "node2"})


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "sweep", SweepTest)
