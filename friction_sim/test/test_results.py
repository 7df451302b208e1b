#!/usr/bin/python3
"""friction_sim.results: a results folder and a bag load into the same columns, with the values the
runs computed (the single block's closed forms, the gauges' force balance), and slip events are handed
on after the frame that closes them whatever order they arrive in."""
import csv
import os
import shutil
import subprocess
import tempfile
import threading
import unittest

import numpy as np
import rosbag
import rospy
import rosunit
from friction_msgs.msg import InterfaceState, SlipEvent, StrainGaugeProfile
from friction_sim import results
from geometry_msgs.msg import WrenchStamped

import built

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def friction_run(scene, out, *assignments):
    command = [built.friction_run(), os.path.join(ROOT, "friction_sim", scene), "--out", out]
    if assignments:
        command += ["--set"] + list(assignments)
    subprocess.run(command, check=True, capture_output=True, timeout=300)


def stamped(msg, seconds):
    msg.header.stamp = rospy.Time.from_sec(seconds)
    return msg


def write_bag(path):
    """Two events, 100 load cells, frames and gauge profiles, as the simulator records them."""
    with rosbag.Bag(path, "w") as bag:
        for step in range(1, 101):
            t = step * 1e-3
            cells = stamped(WrenchStamped(), t)
            cells.wrench.force.x, cells.wrench.force.z = 2.0 * step, -1920.0
            bag.write("/rig/load_cells", cells, cells.header.stamp)
            frame = stamped(InterfaceState(frame_index=step - 1, position=[0.0, 0.07, 0.14],
                                           slip_velocity=[step * 1e-3, 0.0, -step * 1e-3], state=[1, 0, 1]), t)
            bag.write("/rig/interface", frame, frame.header.stamp)
            gauges = stamped(StrainGaugeProfile(height=0.002, position=[0.0, 0.07, 0.14], sigma_xx=[step, 0, 0],
                                                sigma_zz=[-2.0e6] * 3, tau_xz=[0, step, 0]), t)
            bag.write("/rig/strain_gauges", gauges, gauges.header.stamp)
        for index, (onset, force, length) in enumerate([(0.03, 192.0, 0.05), (0.08, 384.0, 0.14)]):
            event = stamped(SlipEvent(index=index, onset_time=onset, end_time=onset + 1e-3, onset_shear_force=force,
                                      onset_normal_force=1920.0, rupture_length=length, slider_length=0.14,
                                      global_event=length == 0.14), onset + 1e-3)
            bag.write("/rig/slip_events", event, event.header.stamp)


def frame_at(t):
    return stamped(InterfaceState(), t)


def event_ending(index, end):
    return stamped(SlipEvent(index=index, end_time=end), end)


def handed_in_order():
    """An EventsAfterFrames and the indices of the events it hands on."""
    handed = []
    return results.EventsAfterFrames(lambda e: handed.append(e.index)), handed


class ResultsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.mkdtemp(prefix="results_test_")
        friction_run("scenes/single_block.yaml", os.path.join(cls.work, "block"))
        friction_run("test/scenes/coarse_2d.yaml", os.path.join(cls.work, "lattice"), "stop.global_events=1")
        cls.bag = os.path.join(cls.work, "run.bag")
        write_bag(cls.bag)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.work)

    def test_the_single_blocks_events_carry_its_closed_forms(self):
        run = results.load(os.path.join(self.work, "block"))
        with open(os.path.join(self.work, "block", "events.csv")) as handle:
            header = next(csv.reader(handle))
        self.assertEqual(header, results.EVENT_COLUMNS)
        self.assertEqual(run.events.names, results.EVENT_COLUMNS)
        self.assertEqual(len(run.events), 3)
        self.assertEqual(run.events["index"].tolist(), [0, 1, 2])
        self.assertEqual(run.events["global"].tolist(), [1, 1, 1])
        # MODEL.md §7.1: slip starts at µ_s N and the force drops by 2(µ_s − µ_k)N, µ_s 0.4, µ_k 0.17, N 1920 N.
        np.testing.assert_allclose(run.events["shear_ratio"], 0.4, rtol=1e-9)
        np.testing.assert_allclose(run.events["end_shear_force_N"], (2 * 0.17 - 0.4) * 1920.0, rtol=1e-6)
        # The loading curve at instruments.loading_curve_rate (10 kHz), its peak the static friction.
        np.testing.assert_allclose(np.diff(run.loading["time_s"][:100]), 1e-4, rtol=1e-9)
        self.assertAlmostEqual(run.loading["shear_force_N"].max(), 0.4 * 1920.0, delta=1e-6)
        self.assertEqual(run.event_nodes["event"].tolist(), [0, 1, 2])
        # Counts are ints, every other number a float, whatever digits the file wrote (1920 for F_Z).
        self.assertEqual(run.events["onset_normal_force_N"].dtype, np.float64)
        self.assertEqual(run.loading["normal_force_N"].dtype, np.float64)
        self.assertEqual(run.events["front_fits_left_out"].dtype, np.int64)
        self.assertEqual(run.stresses["phase"].tolist()[:2], ["onset", "end"])
        self.assertIn("single_block", run.scene)
        self.assertIsNone(run.slip_map)

    def test_gauge_profiles_carry_the_normal_load(self):
        run = results.load(os.path.join(self.work, "lattice"))
        gauges = run.gauges
        # Each event's onset and end, one gauge above each interface node.
        self.assertEqual(gauges.sigma_zz.shape, (2 * len(run.events), len(gauges.x)))
        # At the end of the onset's step: within a step (the stability limit, 0.4 µs) of the event's onset.
        np.testing.assert_allclose(gauges.time[0::2], run.events["onset_time_s"], rtol=0, atol=4e-7)
        self.assertTrue(np.all(gauges.time[1::2] > gauges.time[0::2]))
        # A cut at the gauges' height carries F_Z, 1920 N on a base of 0.14 m × 0.006 m: Σσ_zz·l·B = −F_Z,
        # l = 5 mm, each gauge standing for its column. The node stresses (means of the adjacent cells)
        # give it to 1.2 % at this coarse spacing; the slider's weight is 0.04 %.
        for profile in gauges.sigma_zz:
            self.assertAlmostEqual(profile.sum() * 0.005 * 0.006 / -1920.0, 1.0, delta=0.02)

    def test_the_bag_loads_into_the_folders_columns(self):
        run = results.load(self.bag)
        self.assertEqual(run.events.names, results.EVENT_COLUMNS)
        np.testing.assert_allclose(run.events["shear_ratio"], [0.1, 0.2])
        np.testing.assert_allclose(run.events["length_ratio"], [0.05 / 0.14, 1.0])
        self.assertEqual(run.events["global"].tolist(), [0, 1])
        self.assertEqual(run.loading.names, ["time_s", "shear_force_N", "normal_force_N"])
        np.testing.assert_allclose(run.loading["shear_force_N"], 2.0 * np.arange(1, 101))
        np.testing.assert_allclose(run.loading["normal_force_N"], 1920.0)
        self.assertEqual(run.slip_map.slip_velocity.shape, (100, 3))
        np.testing.assert_allclose(run.slip_map.slip_velocity[:, 2], -np.arange(1, 101) * 1e-3)
        np.testing.assert_allclose(run.slip_map.x, [0.0, 0.07, 0.14])
        self.assertEqual(run.gauges.tau_xz.shape, (100, 3))
        np.testing.assert_allclose(run.gauges.sigma_xx[:, 0], np.arange(1, 101))
        np.testing.assert_allclose(run.gauges.time, np.arange(1, 101) * 1e-3)

    def test_a_counting_column_with_a_missing_cell_reads_as_numbers(self):
        path = os.path.join(self.work, "old_events.csv")
        with open(path, "w", newline="") as handle:
            csv.writer(handle).writerows([["index", "front_fits_left_out", "phase"], ["0", "nan", "loading"],
                                          ["1", "3", "loading"]])
        table = results.read_csv(path)
        self.assertEqual(table["index"].dtype, int)
        np.testing.assert_array_equal(table["front_fits_left_out"], [np.nan, 3.0])
        self.assertEqual(table["phase"].tolist(), ["loading", "loading"])

    @unittest.skipUnless(__import__("importlib").util.find_spec("pandas"), "pandas is not installed")
    def test_a_table_becomes_a_dataframe(self):
        frame = results.load(self.bag).events.to_dataframe()
        self.assertEqual(list(frame.columns), results.EVENT_COLUMNS)
        self.assertEqual(frame["onset_shear_force_N"].tolist(), [192.0, 384.0])

    def test_a_bag_without_events_is_refused_naming_what_it_holds(self):
        with self.assertRaisesRegex(results.BagError, "holds no /rig/precursor_detector/slip_events; its topics: "
                                                      "/rig/interface /rig/load_cells"):
            results.load(self.bag, event_source="detector")

    def test_an_event_waits_for_the_frame_at_or_after_its_end(self):
        order, handed = handed_in_order()
        order.frame(frame_at(1.0))
        order.event(event_ending(0, 1.5))  # arrived before its closing frame
        order.frame(frame_at(1.4))
        self.assertEqual(handed, [])
        order.frame(frame_at(1.5))
        self.assertEqual(handed, [0])
        # An event whose frame came first is handed on at once.
        order.frame(frame_at(2.0))
        order.event(event_ending(1, 1.9))
        self.assertEqual(handed, [0, 1])

    def test_frames_and_events_fed_from_two_threads_hand_each_event_on_once_in_order(self):
        # As rospy feeds them: one thread per topic.
        order, handed = handed_in_order()
        events = [event_ending(k, 1e-3 * k) for k in range(2000)]
        frames = [frame_at(1e-3 * k) for k in range(2000)]
        threads = [threading.Thread(target=lambda: [order.event(e) for e in events]),
                   threading.Thread(target=lambda: [order.frame(f) for f in frames])]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        order.flush()
        self.assertEqual(handed, list(range(2000)))

    def test_a_table_with_a_short_row_is_refused_naming_its_line(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "events.csv")
            with open(path, "w") as handle:
                handle.write("index,onset_time_s\n0,0.1\n1\n")
            with self.assertRaisesRegex(ValueError, "events.csv line 3: 1 cells, the header has 2"):
                results.read_csv(path)

    def test_an_event_released_while_another_is_handed_on_waits_for_it(self):
        # One thread is still handing on event 0 when another releases event 1: 1 must come second.
        handed, in_first, go_on = [], threading.Event(), threading.Event()

        def on_event(event):
            if event.index == 0:
                in_first.set()
                go_on.wait(10)
            handed.append(event.index)

        order = results.EventsAfterFrames(on_event)
        order.frame(frame_at(1.0))
        first = threading.Thread(target=order.event, args=(event_ending(0, 0.5),))
        first.start()
        self.assertTrue(in_first.wait(10))
        second = threading.Thread(target=order.event, args=(event_ending(1, 0.6),))
        second.start()
        second.join(0.5)  # time for it to hand on, were it not to wait
        go_on.set()
        first.join()
        second.join()
        self.assertEqual(handed, [0, 1])

    def test_events_held_at_a_reset_or_the_runs_end_are_handed_on(self):
        order, handed = handed_in_order()
        order.event(event_ending(0, 0.5))
        order.frame(frame_at(0.4))
        order.frame(frame_at(0.1))  # time went back: a reset or a looped bag
        self.assertEqual(handed, [0])
        order.event(event_ending(1, 0.3))
        order.flush()
        self.assertEqual(handed, [0, 1])


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "results", ResultsTest)
