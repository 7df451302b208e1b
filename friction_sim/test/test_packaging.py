#!/usr/bin/python3
"""The three catkin packages as catkin_lint reads them: no problem at -W1 (errors and warnings), so that
they build and install the way catkin users expect (dependencies exported, everything installed); and
the built programs look for their libraries only where their RUNPATH names, and friction_run needs none
of them."""
import os
import re
import subprocess
import unittest

import rosunit

import built

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class PackagingTest(unittest.TestCase):
    def test_catkin_lint_finds_no_problem(self):
        done = subprocess.run(["catkin_lint", "-W1", "--pkg", "friction_msgs", "--pkg", "friction_sim", "--pkg",
                               "friction_rviz", "--package-path", ROOT], capture_output=True, text=True, timeout=300)
        self.assertIn("checked 3 packages and found 0 problems", done.stderr + done.stdout, done.stdout + done.stderr)

    def test_no_library_is_looked_for_in_the_working_directory(self):
        # An empty RUNPATH entry means the working directory to the loader. The simulator node links the
        # core's library and ROS's.
        dynamic = subprocess.run(["readelf", "-d", built.program("rig_simulator")], capture_output=True, text=True,
                                 check=True).stdout
        paths = re.findall(r"\((?:RUNPATH|RPATH)\)\s+Library r(?:un)?path: \[(.*)\]", dynamic)
        self.assertTrue(paths, dynamic)
        for path in paths:
            self.assertNotIn("", path.split(":"), path)

    def test_friction_run_loads_only_the_c_library(self):
        # A process per run: where cmake/core.cmake found the static archives, the core, libstdc++,
        # yaml-cpp, AMD and libgomp are linked in. The build says which it chose.
        linkage = os.environ.get("FRICTION_RUN_LINKAGE")
        if linkage != "static":
            self.skipTest("FRICTION_RUN_LINKAGE is %s, not static (the build sets it)" % linkage)
        dynamic = subprocess.run(["readelf", "-d", built.friction_run()], capture_output=True, text=True,
                                 check=True).stdout
        needed = re.findall(r"\(NEEDED\)\s+Shared library: \[(.*)\]", dynamic)
        self.assertTrue(needed, dynamic)
        for name in needed:  # the C library, its maths and the loader
            self.assertRegex(name, r"^(libc|libm|libmvec)\.so\.\d+$|^ld-linux", dynamic)
        self.assertNotIn("RUNPATH", dynamic)


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "packaging", PackagingTest)
