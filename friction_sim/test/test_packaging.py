#!/usr/bin/python3
"""The three catkin packages as catkin_lint reads them: no problem at -W1 (errors and warnings), so that
they build and install the way catkin users expect (dependencies exported, everything installed)."""
import os
import subprocess
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class PackagingTest(unittest.TestCase):
    def test_catkin_lint_finds_no_problem(self):
        done = subprocess.run(["catkin_lint", "-W1", "--pkg", "friction_msgs", "--pkg", "friction_sim", "--pkg",
                               "friction_rviz", "--package-path", ROOT], capture_output=True, text=True, timeout=300)
        self.assertIn("checked 3 packages and found 0 problems", done.stderr + done.stdout, done.stdout + done.stderr)


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "packaging", PackagingTest)
