#!/usr/bin/python3
"""The offline runner's command line: an argument it cannot read is refused with exit status 2, a bad
override of a scene field or a bad command table with 3, an output directory it cannot write with 4, each
before anything runs, with a message that says what is wrong, and no results directory is written; and a
command table drives the run as the rig's commands do."""
import csv
import os
import pty
import shutil
import subprocess
import tempfile
import unittest

import rosunit

import built

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "friction_sim/scenes/single_block.yaml")


class FrictionRunCommandLineTest(unittest.TestCase):
    def setUp(self):
        self.runner = built.friction_run()
        self.work = tempfile.mkdtemp(prefix="friction_run_test_")
        self.addCleanup(shutil.rmtree, self.work)
        self.out = os.path.join(self.work, "out")

    def refusal(self, *args):
        """friction_run's exit status and standard error for `args`, after checking it wrote nothing."""
        done = subprocess.run([self.runner] + list(args), capture_output=True, text=True, timeout=60)
        self.assertFalse(os.path.exists(self.out), "a refused run wrote its results directory")
        return done.returncode, done.stderr

    def test_an_override_without_key_and_value_is_named(self):
        for assignment in ["pusher.height", "=0.01", "pusher.height="]:
            status, message = self.refusal(SCENE, "--out", self.out, "--set", assignment)
            self.assertEqual(status, 2, assignment)
            self.assertIn("--set needs key=value, got '%s'" % assignment, message)

    def test_a_missing_scene_file_is_named(self):
        status, message = self.refusal()
        self.assertEqual(status, 2)
        self.assertIn("no scene file given", message)
        status, message = self.refusal("--out", self.out, SCENE)
        self.assertEqual(status, 2)
        self.assertIn("the scene file comes first, got '--out'", message)

    def test_an_unknown_argument_is_named(self):
        status, message = self.refusal(SCENE, "--out", self.out, "--sett", "pusher.height=0.01")
        self.assertEqual(status, 2)
        self.assertIn("unknown argument '--sett'", message)

    def test_an_option_missing_its_value_is_named(self):
        for option in ["--set", "--out", "--commands", "--protocol", "--threads"]:
            status, message = self.refusal(SCENE, option)
            self.assertEqual(status, 2, option)
            self.assertIn("%s needs a value" % option, message)

    def test_a_thread_count_that_is_not_a_whole_number_from_one_is_named(self):
        for threads in ["0", "-2", "two", "1.5"]:
            status, message = self.refusal(SCENE, "--out", self.out, "--threads", threads)
            self.assertEqual(status, 2, threads)
            self.assertIn("--threads %s: allowed: a whole number from 1" % threads, message)

    def test_threads_give_the_same_results_to_the_last_digit(self):
        # The default slider at 4 mm/s to its first global event (seven events), its sweeps on two threads.
        scene = os.path.join(ROOT, "friction_sim/scenes/pmma_2d.yaml")
        outputs = {}
        for threads in ["1", "2"]:
            out = os.path.join(self.work, "threads_" + threads)
            done = subprocess.run([self.runner, scene, "--out", out, "--threads", threads, "--set",
                                   'stage.program=[{"mode":"velocity","speed":4.0e-3}]'],
                                  capture_output=True, text=True, timeout=120)
            self.assertEqual(done.returncode, 0, done.stderr)
            with open(os.path.join(out, "events.csv")) as events, open(os.path.join(out, "summary.txt")) as summary:
                outputs[threads] = (events.read(), [line for line in summary if "wall time" not in line])
        self.assertEqual(outputs["1"][0].count("\n"), 8)  # the header and seven events
        self.assertEqual(outputs["2"], outputs["1"])

    def test_a_bad_override_lists_the_field_the_value_and_the_range(self):
        status, message = self.refusal(SCENE, "--out", self.out, "--set", "pusher.height=1")
        self.assertEqual(status, 3)
        self.assertIn("scene refused", message)
        self.assertIn("pusher.height: value 1 is not allowed; allowed: [0,", message)

    def test_an_output_directory_that_cannot_be_created_is_named(self):
        blocker = os.path.join(self.work, "a_file")
        open(blocker, "w").close()
        self.out = os.path.join(blocker, "out")
        status, message = self.refusal(SCENE, "--out", self.out)
        self.assertEqual(status, 4)
        self.assertIn("--out %s: cannot create the directory" % self.out, message)

    def commands(self, rows):
        """A command table of `rows` in the work folder; returns its path."""
        path = os.path.join(self.work, "commands.csv")
        with open(path, "w") as table:
            table.write("time_s,command,speed_m_s,target_m,normal_force_N\n" + "".join(row + "\n" for row in rows))
        return path

    def test_a_bad_command_table_lists_every_problem_before_the_run(self):
        # The table's own problems and what the scene refuses (a speed beyond its stage.max_speed, 1 m/s;
        # F_Z beyond 5 % of E over the base), all at once, each with its line.
        table = self.commands(["0,hold,,,", "0.1,velocity,fast,,", "0.2,velocity,2.0,,", "0.3,normal_load,,,1e9"])
        status, message = self.refusal(SCENE, "--out", self.out, "--commands", table)
        self.assertEqual(status, 3)
        self.assertIn("command table refused (3 problems)", message)
        self.assertIn("%s, line 3: velocity needs speed_m_s as a number, got 'fast'" % table, message)
        self.assertIn("%s, line 4: speed 2 m/s exceeds the stage's max_speed 1 m/s" % table, message)
        self.assertIn("%s, line 5: normal load 1e+09 N is not allowed" % table, message)
        status, message = self.refusal(SCENE, "--out", self.out, "--commands", os.path.join(self.work, "none.csv"))
        self.assertEqual(status, 3)
        self.assertIn("file '%s' cannot be read (No such file or directory)" % os.path.join(self.work, "none.csv"),
                      message)

    def test_commands_drive_the_stage_and_the_normal_load(self):
        # The single block held while F_Z goes from 1920 to 2500 N, then driven at V = 0.4 mm/s from
        # t0 = 0.1 s: it slips first when K·V·(t − t0) = µ_s·F_Z, at t = 0.1 + 0.4 · 2500 / (4e6 · 4e-4)
        # = 0.725 s (0.48 s without the commands).
        table = self.commands(["0,hold,,,", "0.05,normal_load,,,2500", "0.1,velocity,4.0e-4,,"])
        done = subprocess.run([self.runner, SCENE, "--out", self.out, "--commands", table, "--set",
                               "stop.global_events=1"], capture_output=True, text=True, timeout=60)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(self.out, "events.csv")) as events:
            first = next(csv.DictReader(events))
        self.assertAlmostEqual(float(first["onset_time_s"]), 0.725, delta=2e-6)  # dt = 1 µs
        self.assertAlmostEqual(float(first["onset_normal_force_N"]), 2500.0, places=9)
        self.assertAlmostEqual(float(first["shear_ratio"]), 0.4, delta=1e-5)

    def test_one_set_takes_several_assignments(self):
        # F_Z = 2500 N and one global event: the block slips first at t = 0.4 · 2500 / (4e6 · 4e-4) = 0.625 s.
        done = subprocess.run([self.runner, SCENE, "--out", self.out, "--set", "load.normal_force=2500",
                               "stop.global_events=1", "--set", "integrator.time_step=5e-7"],
                              capture_output=True, text=True, timeout=60)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(self.out, "events.csv")) as events:
            rows = list(csv.DictReader(events))
        self.assertEqual(len(rows), 1)
        self.assertAlmostEqual(float(rows[0]["onset_time_s"]), 0.625, delta=1e-6)  # dt = 0.5 µs
        self.assertAlmostEqual(float(rows[0]["onset_normal_force_N"]), 2500.0, places=9)

    def test_a_terminal_sees_progress_and_a_pipe_does_not(self):
        # About 3 s of wall time: 6 s simulated in steps of 1 µs.
        args = [self.runner, SCENE, "--out", self.out, "--set", "stop.global_events=0", "stop.time=6"]
        piped = subprocess.run(args, capture_output=True, text=True, timeout=120)
        self.assertEqual(piped.returncode, 0, piped.stderr)
        self.assertNotIn("\x1b", piped.stdout + piped.stderr)
        self.assertNotIn("steps/s,", piped.stderr)
        master, terminal = pty.openpty()
        with subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=terminal) as shown:
            os.close(terminal)
            seen = b""
            while True:
                try:
                    chunk = os.read(master, 4096)
                except OSError:  # the run closed the terminal
                    break
                if not chunk:
                    break
                seen += chunk
        os.close(master)
        self.assertEqual(shown.returncode, 0)
        lines = seen.decode().split("\r\x1b[K")
        progress = [line for line in lines if "steps/s" in line]
        self.assertTrue(progress, seen)
        self.assertRegex(progress[-1], r"^t = [0-9.e+-]+ s of 6 s, [0-9]+ steps/s, [0-9]+ jumps/s, [0-9]+ events, "
                                       r"at most [0-9]+ s left$")

    def peak_memory_kb(self, global_events):
        """The peak resident memory (kB) of the single block's run (fast-forward) to `global_events` events,
        after checking that every event is in events.csv."""
        out = os.path.join(self.work, "events_%d" % global_events)
        with subprocess.Popen([self.runner, SCENE, "--out", out, "--set", "integrator.fast_forward=true",
                               "instruments.loading_curve_rate=10", "stop.time=1e5",
                               "stop.global_events=%d" % global_events], stdout=subprocess.DEVNULL) as run:
            _, status, usage = os.wait4(run.pid, 0)
            run.returncode = os.waitstatus_to_exitcode(status)
        self.assertEqual(run.returncode, 0)
        with open(os.path.join(out, "events.csv")) as events:
            self.assertEqual(sum(1 for _ in csv.DictReader(events)), global_events)
        return usage.ru_maxrss

    def test_memory_stays_flat_however_many_events(self):
        # The single block's stick-slip, 10^3 and then 2 * 10^4 cycles (240 s and 4800 s simulated): the
        # tables go to their files as the run goes and only the latest events are kept, so the longer run
        # needs no more memory. Measured: 10.2 MB peak for both; with every event and sample kept, 10.2 and 20.6 MB.
        few, many = self.peak_memory_kb(1000), self.peak_memory_kb(20000)
        self.assertLess(many - few, 1024, "%d kB for 10^3 events, %d kB for 2 * 10^4" % (few, many))

    def test_a_protocol_runs_as_the_controller_runs_it(self):
        # F_Z ramped to 2500 N over 10 ms with the stage held, a hold to t0 = 0.1 s, then V = 0.4 mm/s:
        # the block slips first at t = t0 + mu_s F_Z / (K V) = 0.1 + 0.4 * 2500 / (4e6 * 4e-4) = 0.725 s,
        # and the protocol's end (one global event), not the scene's (three), ends the run.
        protocol = os.path.join(self.work, "protocol.yaml")
        with open(protocol, "w") as handle:
            handle.write("steps:\n"
                         "  - {action: normal_load, normal_force: 2500, ramp_time: 0.01}\n"
                         "  - {action: hold, duration: 0.09}\n"
                         "  - {action: drive, speed: 4.0e-4, duration: .inf}\n"
                         "end: {global_events: 1}\n")
        done = subprocess.run([self.runner, SCENE, "--out", self.out, "--protocol", protocol],
                              capture_output=True, text=True, timeout=60)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("commands: 23 of 23 applied", done.stdout)  # a hold, 20 ramp steps, a hold, a drive
        self.assertIn("reached 1 global slip event", done.stdout)
        with open(os.path.join(self.out, "events.csv")) as events:
            rows = list(csv.DictReader(events))
        self.assertEqual(len(rows), 1)
        self.assertAlmostEqual(float(rows[0]["onset_time_s"]), 0.725, delta=2e-6)  # dt = 1 µs
        self.assertAlmostEqual(float(rows[0]["shear_ratio"]), 0.4, delta=1e-5)
        # With fast-forward the held block jumps from one F_Z command to the next, and the load cells
        # sampled across each jump read the F_Z just set: 1920 + 29 k N after the k-th of the ramp's 20
        # steps, at (k - 1) · 0.5 ms (they had ramped from the F_Z before it, a command late).
        ramp = os.path.join(self.work, "ramp")
        done = subprocess.run([self.runner, SCENE, "--out", ramp, "--protocol", protocol, "--set",
                               "integrator.fast_forward=true"], capture_output=True, text=True, timeout=60)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(ramp, "loading.csv")) as loading:
            samples = [row for row in csv.DictReader(loading) if float(row["time_s"]) < 0.0099]
        checked = 0
        for row in samples:
            k, into = divmod(round(float(row["time_s"]) / 1e-4), 5)
            if into > 0:  # not on a command's own time, where the step's end and the command coincide
                self.assertAlmostEqual(float(row["normal_force_N"]), 1920.0 + 29.0 * (k + 1), places=6, msg=row)
                checked += 1
        self.assertEqual(checked, 79)
        self.out = os.path.join(self.work, "refused")
        status, message = self.refusal(SCENE, "--out", self.out, "--protocol", protocol, "--commands", protocol)
        self.assertEqual(status, 2)
        self.assertIn("--commands and --protocol both drive the stage; give one", message)
        # What the scene refuses, named by the protocol's step, once for a whole ramp.
        with open(protocol, "w") as handle:
            handle.write("steps:\n"
                         "  - {action: normal_load, normal_force: 1.0e9, ramp_time: 0.01}\n"
                         "  - {action: drive, speed: 2.0, duration: .inf}\n"
                         "end: {global_events: 1}\n")
        status, message = self.refusal(SCENE, "--out", self.out, "--protocol", protocol)
        self.assertEqual(status, 3)
        self.assertIn("protocol refused (2 problems)", message)
        self.assertIn("%s, steps[0]: normal load 1e+09 N is not allowed" % protocol, message)
        self.assertIn("%s, steps[1]: speed 2 m/s exceeds the stage's max_speed 1 m/s" % protocol, message)


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "friction_run_command_line", FrictionRunCommandLineTest)
