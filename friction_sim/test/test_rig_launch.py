#!/usr/bin/python3
"""scripts/rig_launch.sh's exit status: roslaunch itself exits 0 when a node refuses its input, so the
script reads the nodes' exit codes and fails, naming the node, when any node refused; a run that ends
cleanly exits 0. Each launch brings up its own private master on a free port."""
import os
import subprocess
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RIG_LAUNCH = os.path.join(ROOT, "scripts/rig_launch.sh")
RIG = os.path.join(ROOT, "launch/rig.launch")
SINGLE_BLOCK = os.path.join(ROOT, "friction_sim/scenes/single_block.yaml")


def launch(*args):
    done = subprocess.run([RIG_LAUNCH, RIG] + list(args), capture_output=True, text=True, timeout=120)
    return done.returncode, done.stdout + done.stderr


class RigLaunchStatusTest(unittest.TestCase):
    def test_a_refused_scene_fails_the_launch_and_names_the_simulator(self):
        status, output = launch("overrides:=pusher.height=1", "analysis:=false")
        self.assertEqual(status, 1, output)
        self.assertIn("/rig/simulator: scene refused", output)
        self.assertIn("pusher.height: value 1 is not allowed", output)
        self.assertIn("rig_launch: failed: rig_simulator (exit code 2)", output)

    def test_a_refused_protocol_fails_the_launch_and_names_the_controller(self):
        status, output = launch("protocol:=/nonexistent/protocol.yaml", "analysis:=false")
        self.assertEqual(status, 1, output)
        self.assertIn("/rig/controller: protocol refused", output)
        self.assertIn("rig_launch: failed: stage_controller (exit code 2)", output)

    def test_a_run_that_reaches_its_stop_condition_succeeds(self):
        # The single block slips at µ_s·F_Z = 0.4 × 1920 N three times and stops (its scene's stop).
        status, output = launch("scene:=" + SINGLE_BLOCK, "controller:=false", "analysis:=false")
        self.assertEqual(status, 0, output)
        self.assertIn("reached 3 global slip event(s)", output)
        self.assertIn("mu_s,macro = F_X/F_Z at the first global event: 0.4", output)
        self.assertNotIn("rig_launch: failed", output)


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "rig_launch_status", RigLaunchStatusTest)
