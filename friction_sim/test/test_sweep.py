#!/usr/bin/python3
"""The sweep tool (scripts/sweep.py) on the single-block scene, whose onset force is µ_s·F_Z exactly:
every combination runs, a refused run is reported without losing the others, a rerun skips what is
done, and runs spread over "remote" machines through GNU parallel's --sshlogin (with an ssh stand-in
that runs the command here, so that no ssh server is needed), with and without a shared file system."""
import csv
import io
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

import rosunit
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import sweep  # noqa: E402

import built  # noqa: E402

with open(os.path.join(ROOT, "friction_sim/scenes/single_block.yaml")) as scene:
    STATIC_COEFFICIENT = yaml.safe_load(scene)["friction"]["static_coefficient"]


class SweepTest(unittest.TestCase):
    def setUp(self):
        runner = mock.patch.object(sweep, "RUNNER", built.friction_run())
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

    def test_every_run_follows_the_sweeps_protocol(self):
        # The protocol drives the block at 4 mm/s and ends after two global events; the scene alone would
        # stop after three.
        path = os.path.join(self.work, "protocol.yaml")
        with open(path, "w") as handle:
            handle.write("base: friction_sim/scenes/single_block.yaml\n"
                         "protocol: friction_sim/test/protocols/two_global_events.yaml\n"
                         "vary: {load.normal_force: [1000, 2000]}\n")
        rows, failed = sweep.run(path, jobs=2, out=os.path.join(self.work, "out"))
        self.assertEqual(failed, [])
        self.assert_onsets_follow_amontons(rows, [1000, 2000])

    def test_a_refused_run_is_reported_and_the_others_are_kept(self):
        out = os.path.join(self.work, "out")
        with mock.patch("sys.stderr", new_callable=io.StringIO) as errors:
            rows, failed = sweep.run(self.write_sweep("[1000, 2000, -5]"), jobs=2, out=out)
        self.assertEqual(failed, ["normal_force=-5"])
        # The reason is in the report, not only in the run's log.
        self.assertIn("load.normal_force: value -5 is not allowed", errors.getvalue())
        self.assert_onsets_follow_amontons(rows, [1000.0, 2000.0])
        with open(os.path.join(out, "events.csv")) as handle:
            self.assertEqual(len(list(csv.DictReader(handle))), 4)
        with open(os.path.join(out, "runs", "normal_force=-5", "log.txt")) as handle:
            self.assertIn("normal_force", handle.read())

    def test_a_sweep_file_that_cannot_be_read_is_named(self):
        with self.assertRaises(SystemExit) as missing:
            sweep.run(os.path.join(self.work, "nonexistent.yaml"))
        self.assertIn("nonexistent.yaml cannot be read", str(missing.exception))

    def test_a_sweep_file_of_the_wrong_shape_is_refused_naming_each_key(self):
        path = os.path.join(self.work, "shapes.yaml")
        with open(path, "w") as handle:
            handle.write("base: friction_sim/scenes/single_block.yaml\n"
                         "set: [stop.global_events]\n"
                         "vary: {load.normal_force: 1000, stage.program: []}\n"
                         "cases: {pusher.height: 0.01}\n")
        with self.assertRaises(SystemExit) as refused:
            sweep.run(path, out=os.path.join(self.work, "out"))
        message = str(refused.exception)
        for problem in ["set: expected a mapping", "vary.load.normal_force: expected a non-empty list of values, got 1000",
                        "vary.stage.program: expected a non-empty list", "cases: expected a list of mappings"]:
            self.assertIn(problem, message)
        self.assertFalse(os.path.exists(os.path.join(self.work, "out")))

    def test_runs_whose_directories_would_be_one_are_refused(self):
        # Two stage programs that differ past the 40 characters a directory name keeps of a value.
        program = '[{"mode":"velocity","speed":4.0e-4,"duration":0.001},{"mode":"hold","speed":%s}]'
        path = os.path.join(self.work, "programs.yaml")
        with open(path, "w") as handle:
            yaml.safe_dump({"base": "friction_sim/scenes/single_block.yaml",
                            "vary": {"stage.program": [program % "0", program % "0.0"]}}, handle)
        with self.assertRaises(SystemExit) as refused:
            sweep.run(path, out=os.path.join(self.work, "out"))
        self.assertIn("share program=", str(refused.exception))

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
            commands = [line.split("\t")[-1] for line in handle.read().splitlines() if not line.startswith("Seq")]
        self.assertEqual(sum("normal_force=1000" in c for c in commands), 1)
        self.assertEqual(sum("normal_force=-5" in c for c in commands), 2)

    def test_a_value_added_to_the_sweep_runs_alone(self):
        # The runs that finished are kept, whatever their place in the new list.
        out = os.path.join(self.work, "out")
        sweep.run(self.write_sweep("[1000, 3000]"), jobs=1, out=out)
        summaries = {force: os.path.join(out, "runs", "normal_force=%d" % force, "summary.txt") for force in (1000, 3000)}
        finished = {force: os.stat(path).st_mtime_ns for force, path in summaries.items()}
        rows, failed = sweep.run(self.write_sweep("[1000, 2000, 3000]"), jobs=1, out=out)
        self.assertEqual(failed, [])
        self.assertEqual({force: os.stat(path).st_mtime_ns for force, path in summaries.items()}, finished)
        self.assert_onsets_follow_amontons(rows, [1000.0, 2000.0, 3000.0])
        with open(os.path.join(out, "joblog.txt")) as handle:
            commands = [line.split("\t")[-1] for line in handle.read().splitlines() if not line.startswith("Seq")]
        self.assertEqual([sum("normal_force=%d" % force in c for c in commands) for force in (1000, 2000, 3000)],
                         [1, 1, 1])

    def write_ssh_stand_in(self, run_on_host):
        """An ssh that runs the command here, through run_on_host (a shell line given $HOST and the
        remote command in $@), and records the hosts it was asked for."""
        calls = os.path.join(self.work, "ssh_calls.txt")
        stand_in = os.path.join(self.work, "ssh")
        with open(stand_in, "w") as handle:
            # parallel calls `ssh HOST -- COMMAND...`, the command meant for the remote shell. sshd sets
            # SHELL, which parallel's remote side runs the job with (without it the job silently does
            # nothing and exits 0; CI runs the tests without SHELL).
            handle.write('#!/bin/sh\nHOST=$1\necho "$HOST" >> %s\nshift\n[ "$1" = "--" ] && shift\n'
                         'SHELL=/bin/sh; export SHELL\n%s\n' % (calls, run_on_host))
        # Through /bin/sh, so that a temporary directory mounted noexec does not matter.
        return mock.patch.dict(os.environ, PARALLEL_SSH="/bin/sh " + stand_in), calls

    def hosts_called(self, calls):
        with open(calls) as handle:
            return set(handle.read().split())

    def test_runs_spread_over_remote_hosts(self):
        environment, calls = self.write_ssh_stand_in('exec /bin/sh -c "$*"')
        with environment:
            rows, failed = sweep.run(self.write_sweep("[1000, 2000, 3000, 4000]"), hosts="1/node1,1/node2",
                                     out=os.path.join(self.work, "out"))
        self.assertEqual(failed, [])
        self.assert_onsets_follow_amontons(rows, [1000.0, 2000.0, 3000.0, 4000.0])
        self.assertEqual(self.hosts_called(calls), {"node1", "node2"})

    def test_remote_hosts_need_not_share_the_file_system(self):
        """Each stand-in host sees its own disk mounted over the sweep's output directory, so a run's
        results reach this machine only if the sweep brings them back."""
        out, disks = os.path.join(self.work, "out"), os.path.join(self.work, "disks")
        os.makedirs(os.path.join(disks, "probe"))
        os.makedirs(out)
        probe = subprocess.run(["unshare", "--mount", "mount", "--bind", os.path.join(disks, "probe"), out],
                               capture_output=True)
        if probe.returncode != 0:
            self.skipTest("no mount namespace here to give each host its own disk: %s" % probe.stderr.strip())
        environment, calls = self.write_ssh_stand_in(
            'mkdir -p %s/$HOST\nexec unshare --mount /bin/sh -c \'mount --bind "$0" "$1" && exec /bin/sh -c "$2"\' '
            '%s/$HOST %s "$*"' % (disks, disks, out))
        with environment:
            rows, failed = sweep.run(self.write_sweep("[1000, 2000, 3000, 4000]"), hosts="1/node1,1/node2",
                                     out=out)
        self.assertEqual(failed, [])
        self.assert_onsets_follow_amontons(rows, [1000.0, 2000.0, 3000.0, 4000.0])
        ran_on = {host: set(name for name in os.listdir(os.path.join(disks, host, "runs"))
                            if os.path.exists(os.path.join(disks, host, "runs", name, "summary.txt")))
                  for host in ("node1", "node2")}
        self.assertTrue(ran_on["node1"] and ran_on["node2"], ran_on)
        self.assertEqual(ran_on["node1"] | ran_on["node2"], set(os.listdir(os.path.join(out, "runs"))))
        self.assertFalse(ran_on["node1"] & ran_on["node2"])


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "sweep", SweepTest)
