#!/usr/bin/python3
"""The offline runner's command line: an argument it cannot read is refused with exit status 2, a bad
override of a scene field with 3, an output directory it cannot write with 4, each before anything runs,
with a message that says what is wrong, and no results directory is written."""
import os
import shutil
import subprocess
import tempfile
import unittest

import rosunit
from catkin.find_in_workspaces import find_in_workspaces

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "friction_sim/scenes/single_block.yaml")


class FrictionRunCommandLineTest(unittest.TestCase):
    def setUp(self):
        runners = find_in_workspaces(["libexec"], project="friction_sim", path="friction_run", first_match_only=True)
        self.assertTrue(runners, "friction_run is not built")
        self.runner = runners[0]
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
        for option in ["--set", "--out"]:
            status, message = self.refusal(SCENE, option)
            self.assertEqual(status, 2, option)
            self.assertIn("%s needs a value" % option, message)

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


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "friction_run_command_line", FrictionRunCommandLineTest)
