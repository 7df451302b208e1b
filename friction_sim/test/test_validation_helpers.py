#!/usr/bin/python3
"""The helpers behind VALIDATION.md §10.4 and §10.6 (scripts/validation_rate_state.py) on small tables
whose answers are known: the invaded extent of a run, the slides after holds of a protocol, the ageing
slope, and the contacts' age and the load's concentration at each slide's strongest event."""
import csv
import math
import os
import shutil
import sys
import tempfile
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import validation_report  # noqa: E402,F401  (validation_rate_state uses its helpers once both are loaded)
import validation_rate_state as vrs  # noqa: E402


def event(index, ratio, length_ratio, is_global=False, onset=0.0):
    return {"index": str(index), "global": "1" if is_global else "0", "shear_ratio": str(ratio),
            "length_ratio": str(length_ratio), "rupture_length_m": str(0.14 * length_ratio),
            "onset_time_s": str(onset), "mean_slip_m": "1e-6"}


class ValidationHelpersTest(unittest.TestCase):
    def setUp(self):
        self.work = tempfile.mkdtemp(prefix="validation_helpers_")
        self.addCleanup(shutil.rmtree, self.work)

    def test_the_largest_extent_reached_so_far(self):
        # A creeping patch's small slips between two fronts leave the extent at the fronts' reach.
        events = [event(0, 0.20, 0.10), event(1, 0.25, 0.40), event(2, 0.26, 0.05), event(3, 0.27, 0.20),
                  event(4, 0.30, 0.55), event(5, 0.35, 1.0, is_global=True), event(6, 0.36, 0.9)]
        self.assertEqual(vrs.reach_envelope(events), [(0.20, 0.10), (0.25, 0.40), (0.26, 0.40), (0.27, 0.40),
                                                       (0.30, 0.55)])
        envelope = vrs.reach_envelope(events)
        self.assertEqual(vrs.reach_at(envelope, 0.19), 0.0)
        self.assertEqual(vrs.reach_at(envelope, 0.28), 0.40)
        self.assertEqual(vrs.reach_at(envelope, 0.50), 0.55)  # the global event is not a precursor

    def test_slides_after_holds_start_and_end_where_the_protocol_says(self):
        protocol = os.path.join(self.work, "protocol.yaml")
        with open(protocol, "w") as handle:
            handle.write("steps:\n  - {action: drive, speed: 4.0e-4, duration: 1.0}\n"
                         "  - {action: hold, duration: 0.5}\n  - {action: drive, speed: 4.0e-4, duration: 0.3}\n"
                         "  - {action: hold, duration: 10.0}\n  - {action: drive, speed: 4.0e-4, duration: 0.3}\n")
        windows = vrs.slides_after_holds(protocol)
        self.assertEqual(len(windows), 2)
        for (hold, begin, end), expected in zip(windows, [(0.5, 1.5, 1.8), (10.0, 11.8, 12.1)]):
            for value, wanted in zip((hold, begin, end), expected):
                self.assertAlmostEqual(value, wanted, places=12)

    def test_log_slope_of_a_logarithm_and_too_few_points(self):
        points = [(hold, 0.4 + 0.02 * math.log(hold)) for hold in (0.1, 1.0, 10.0, 100.0)]
        self.assertAlmostEqual(vrs.log_slope(points), 0.02, places=12)
        self.assertAlmostEqual(vrs.log_slope(points + [(1000.0, math.nan)]), 0.02, places=12)
        self.assertTrue(math.isnan(vrs.log_slope([(1.0, 0.4), (10.0, math.nan)])))

    def test_age_and_concentration_at_each_slides_strongest_event(self):
        # Two slides; the second's strongest event is event 2 (F_X/F_Z 0.5), not event 1 (0.3). Nodes at
        # x = 0 and 0.005 m lie within a trailing length of 0.01 m; the node at 0.05 m does not, and the
        # one at 0.008 m has lost contact and counts for nothing.
        with open(os.path.join(self.work, "events.csv"), "w") as handle:
            handle.write("index,onset_time_s,shear_ratio\n0,1.0,0.4\n1,2.0,0.3\n2,2.5,0.5\n3,9.0,0.9\n")
        rows = [(0, 0.0, 1e6, 0.4e6, 0.40), (0, 0.005, 1e6, 0.6e6, 0.42), (0, 0.05, 1e6, 0.1e6, 0.50),
                (1, 0.0, 1e6, 0.9e6, 0.90), (2, 0.0, 2e6, 1.2e6, 0.45), (2, 0.005, 2e6, 1.0e6, 0.47),
                (2, 0.008, 0.0, 0.0, 0.10), (2, 0.05, 2e6, 0.2e6, 0.55)]
        with open(os.path.join(self.work, "stresses.csv"), "w") as handle:
            writer = csv.writer(handle)
            writer.writerow(["event", "phase", "x_m", "interface_normal_stress_Pa", "interface_shear_stress_Pa",
                             "interface_static_coefficient"])
            for row in rows:
                writer.writerow([row[0], "onset", row[1], row[2], row[3], row[4]])
                writer.writerow([row[0], "end", row[1], row[2], 0.0, 0.0])
        ages = vrs.ages_at_peaks(self.work, [(0.1, 0.5, 1.5), (1.0, 1.5, 3.0), (10.0, 4.0, 5.0)], 0.01)
        young, rest, concentration = ages[0]
        self.assertAlmostEqual(young, 0.41, places=12)  # median of 0.40 and 0.42
        self.assertAlmostEqual(rest, 0.50, places=12)
        self.assertAlmostEqual(concentration, 0.5 / 0.4, places=12)  # median τ/σ of 0.4 and 0.6, over 0.4
        young, rest, concentration = ages[1]
        self.assertAlmostEqual(young, 0.46, places=12)
        self.assertAlmostEqual(rest, 0.55, places=12)
        self.assertAlmostEqual(concentration, 0.55 / 0.5, places=12)  # τ/σ 0.6 and 0.5
        self.assertTrue(all(math.isnan(value) for value in ages[2]))  # no event in that slide


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "validation_helpers", ValidationHelpersTest)
