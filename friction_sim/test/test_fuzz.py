#!/usr/bin/python3
"""Fuzzed scenes through friction_run: seeded mutations of the shipped scenes (one or two numeric fields
set to zero, negative, tiny, huge, NaN, infinite or the largest int) each either run (0) or are refused
(3) with every problem naming its field; none crashes, runs out of 4 GB or hangs (20 s each; every case
ends at 0.2 ms of simulated time). 200 cases here (about 30 s); FUZZ_CASES and FUZZ_SEED set others."""
import os
import random
import re
import resource
import subprocess
import tempfile
import unittest

import rosunit

import built

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = ["pmma_2d", "pmma_2d_rate_state", "pmma_1d_side", "pmma_1d_top", "single_block", "rate_state"]
FIELDS = ["geometry.length", "geometry.height", "geometry.width", "material.density", "material.youngs_modulus",
          "material.damping_coefficient", "lattice.nodes_x", "lattice.nodes_z", "lattice.foundation_ratio",
          "chain.blocks", "chain.tilt", "chain.torque_share", "friction.static_coefficient",
          "friction.kinetic_coefficient", "friction.interfacial_stiffness", "load.normal_force", "pusher.stiffness",
          "pusher.height", "stage.max_speed", "integrator.time_step", "instruments.loading_curve_rate",
          "instruments.gauge_height", "instruments.front_fit_nodes", "instruments.event_slip_speed"]
VALUES = ["0", "-1", "1e-320", "1e-300", "1e-12", "1e12", "1e300", "1e308", ".nan", ".inf", "-.inf", "2147483647",
          "2.5", "3", "1e6"]
# "field: value ..." or "field/field: ...", as every refusal starts.
NAMES_A_FIELD = re.compile(r"  - [a-z_]+(\.[a-z_\[\]0-9]+)*(/[a-z_]+(\.[a-z_\[\]0-9]+)*)*: ")


def four_gigabytes():
    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))


class FuzzTest(unittest.TestCase):
    def test_every_fuzzed_scene_runs_or_is_refused_naming_its_fields(self):
        runner = built.friction_run()
        rng = random.Random(int(os.environ.get("FUZZ_SEED", "1")))
        out = tempfile.mkdtemp(prefix="fuzz_")
        outcomes = {}
        for _ in range(int(os.environ.get("FUZZ_CASES", "200"))):
            scene = os.path.join(ROOT, "friction_sim/scenes", rng.choice(SCENES) + ".yaml")
            mutations = ["%s=%s" % (rng.choice(FIELDS), rng.choice(VALUES)) for _ in range(rng.randint(1, 2))]
            case = "%s %s" % (os.path.basename(scene), " ".join(mutations))
            try:
                done = subprocess.run([runner, scene, "--out", out, "--set"] + mutations + ["stop.time=2e-4"],
                                      capture_output=True, text=True, timeout=20, preexec_fn=four_gigabytes)
            except subprocess.TimeoutExpired:
                self.fail("hung: " + case)
            self.assertIn(done.returncode, (0, 3), "%s: %s" % (case, done.stderr[-500:]))
            outcomes[done.returncode] = outcomes.get(done.returncode, 0) + 1
            problems = [line for line in done.stderr.splitlines() if line.startswith("  - ")]
            if done.returncode == 3:
                self.assertTrue(problems, case)
            for problem in problems:
                self.assertRegex(problem, NAMES_A_FIELD, case)
        # Both outcomes occur: the mutations reach past the checks as well as into them.
        self.assertGreater(outcomes.get(0, 0), 0, outcomes)
        self.assertGreater(outcomes.get(3, 0), 0, outcomes)


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "fuzz", FuzzTest)
