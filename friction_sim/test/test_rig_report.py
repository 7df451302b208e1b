#!/usr/bin/python3
"""rig_report reads the rig's topics by name: a bag of `rosbag record -a` holds the slip events of the
simulator and of the precursor detector, and each event is tabled once, from the source asked for; a
bag without the rig's load cells is refused with the topics it does hold."""
import csv
import os
import shutil
import struct
import subprocess
import tempfile
import unittest

import rosbag
import rospy
import rosunit
from friction_sim import results
from friction_msgs.msg import InterfaceState, SlipEvent, StageCommand, StageState
from geometry_msgs.msg import WrenchStamped
from std_msgs.msg import String

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RIG_REPORT = os.path.join(ROOT, "friction_sim/scripts/rig_report")
F_Z = 1920.0
SCENE = "name: synthetic\nload: {normal_force: 1920}\n"


def event(index, onset, shear_ratio, rupture_length, slider_length=0.14):
    msg = SlipEvent()
    msg.header.stamp = rospy.Time.from_sec(onset + 0.001)
    msg.index, msg.onset_time, msg.end_time = index, onset, onset + 0.001
    msg.onset_shear_force, msg.onset_normal_force = shear_ratio * F_Z, F_Z
    msg.rupture_length, msg.slider_length = rupture_length, slider_length
    msg.global_event = rupture_length == 0.14
    return msg


def write_bag(path, namespace="/rig", detector=True, slider_length=0.14, also=None, normal_load_rise=0.0,
              commands=True, scene_again=None, resets=0, first_resets=0, ageing=False, frames_from=0,
              frames_lost=(), events_lost=()):
    """Load cells and frames for 0.1 s (F_Z rising by `normal_load_rise` N per ms), two events from the
    simulator and, unless not `detector`, the same two, with the detector's slightly later reading of F_X,
    from the detector; `also` another rig's namespace with the same; unless not `commands`, a drive and a
    normal-load command as applied; `scene_again` a second scene message (the rig's with its run end);
    stage states counting `resets` during the recording, from `first_resets` before it; with `ageing`,
    frames whose static coefficients rise with time; `frames_from` the index of the first frame written,
    `frames_lost` and `events_lost` the indices of frames and events left out, as a late or lossy recorder
    leaves them."""
    if also:
        write_bag(path + ".also", also, detector, slider_length)
    with rosbag.Bag(path, "w") as bag:
        if also:
            with rosbag.Bag(path + ".also") as other:
                for topic, msg, stamp in other.read_messages():
                    bag.write(topic, msg, stamp)
        bag.write(namespace + "/scene", String(data=SCENE), rospy.Time(0, 1))
        if scene_again:
            bag.write(namespace + "/scene", String(data=scene_again), rospy.Time(0, 2))
        for stamp, count in [(0.01, first_resets), (0.05, first_resets + resets)]:
            state = StageState(resets=count)
            state.header.stamp = rospy.Time.from_sec(stamp)
            bag.write(namespace + "/stage_state", state, state.header.stamp)
        if commands:
            drive = StageCommand(mode=StageCommand.VELOCITY, speed=4e-4, target=0.5, normal_force=7.0)
            bag.write(namespace + "/applied_commands", drive, rospy.Time(0, 2))
            load = StageCommand(mode=StageCommand.NORMAL_LOAD, normal_force=2500.0)
            load.header.stamp = rospy.Time.from_sec(0.05)
            bag.write(namespace + "/applied_commands", load, load.header.stamp)
        for step in range(1, 101):
            stamp = rospy.Time.from_sec(step * 1e-3)
            wrench = WrenchStamped()
            wrench.header.stamp = stamp
            wrench.wrench.force.x, wrench.wrench.force.z = 4.0 * step, -(F_Z + normal_load_rise * step)
            bag.write(namespace + "/load_cells", wrench, stamp)
            frame = InterfaceState()
            frame.header.stamp = stamp
            frame.frame_index = step - 1
            if frame.frame_index < frames_from or frame.frame_index in frames_lost:
                continue
            frame.position = [0.0, 0.07, 0.14]
            frame.slip_velocity = [0.0, 0.0, 0.0]
            frame.state = [0, 0, 0]
            frame.static_coefficient = [0.5 + 1e-4 * step] * 3 if ageing else [0.4] * 3
            bag.write(namespace + "/interface", frame, stamp)
        sources = [("/slip_events", 0.0)] + ([("/precursor_detector/slip_events", 1e-4)] if detector else [])
        for source, later in sources:
            for msg in [event(0, 0.03, 0.1 + later, 0.05, slider_length), event(1, 0.08, 0.2 + later, 0.14, slider_length)]:
                if msg.index not in events_lost:
                    bag.write(namespace + source, msg, msg.header.stamp)


class RigReportTest(unittest.TestCase):
    def setUp(self):
        self.work = tempfile.mkdtemp(prefix="rig_report_test_")
        self.addCleanup(shutil.rmtree, self.work)
        self.bag = os.path.join(self.work, "run.bag")
        write_bag(self.bag)

    def report(self, *args):
        return subprocess.run(["/usr/bin/python3", RIG_REPORT, self.bag, "--out", self.work] + list(args),
                              capture_output=True, text=True, timeout=120)

    def table(self):
        with open(os.path.join(self.work, "events.csv")) as handle:
            return list(csv.DictReader(handle))

    def test_each_event_is_tabled_once_from_the_simulator_by_default(self):
        done = self.report()
        self.assertEqual(done.returncode, 0, done.stderr)
        rows = self.table()
        self.assertEqual([float(row["shear_ratio"]) for row in rows], [0.1, 0.2])
        self.assertEqual([row["global"] for row in rows], ["0", "1"])
        # friction_run's columns: the forces in newtons and the end time too.
        self.assertEqual([float(row["onset_shear_force_N"]) for row in rows], [0.1 * F_Z, 0.2 * F_Z])
        self.assertEqual([float(row["end_time_s"]) for row in rows], [0.031, 0.081])
        for figure in ["loading_curve.png", "precursors.png", "slip_map.png"]:
            self.assertTrue(os.path.exists(os.path.join(self.work, figure)), figure)
        with open(os.path.join(self.work, "scene.yaml")) as scene:
            self.assertEqual(scene.read(), SCENE)  # the scene as run, from the bag
        # The commands as applied, each with the fields its mode uses (a velocity command's target is
        # not one of them).
        with open(os.path.join(self.work, "stage_commands.csv")) as handle:
            self.assertEqual(list(csv.reader(handle)), [
                ["time_s", "command", "speed_m_s", "target_m", "normal_force_N"],
                ["0.000000000", "velocity", "0.0004", "", ""],
                ["0.050000000", "normal_load", "", "", "2500.0"]])
        # And the command that reruns the run from the two.
        self.assertIn("friction_run {0}/scene.yaml --commands {0}/stage_commands.csv --out {0}/rerun".format(self.work),
                      done.stdout)

    def test_static_friction_is_mapped_only_where_it_changes(self):
        self.assertEqual(self.report().returncode, 0)
        self.assertFalse(os.path.exists(os.path.join(self.work, "static_friction.png")))  # µ_s = 0.4 throughout
        write_bag(self.bag, ageing=True)
        done = self.report()
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertTrue(os.path.exists(os.path.join(self.work, "static_friction.png")))
        self.assertIn("static_friction.png", done.stdout)

    def test_the_scene_is_the_last_recorded_and_a_bag_without_commands_says_so(self):
        # The rig records its scene again with the run's end when a controller sets it.
        with_end = SCENE + "stop: {global_events: 4, time: .inf}\n"
        write_bag(self.bag, commands=False, scene_again=with_end)
        done = self.report()
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(self.work, "scene.yaml")) as scene:
            self.assertEqual(scene.read(), with_end)
        self.assertFalse(os.path.exists(os.path.join(self.work, "stage_commands.csv")))
        self.assertIn("the bag holds no applied commands: no stage_commands.csv", done.stdout)
        self.assertIn("friction_run {0}/scene.yaml --out {0}/rerun".format(self.work), done.stdout)

    def test_a_bag_that_spans_a_reset_offers_no_rerun(self):
        write_bag(self.bag, resets=1)
        done = self.report()
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("the bag spans 1 reset(s): it holds 2 runs on one time axis", done.stdout)
        self.assertNotIn("friction_run", done.stdout)
        # One recorded after an earlier reset holds one run.
        write_bag(self.bag, first_resets=1)
        done = self.report()
        self.assertNotIn("reset", done.stdout)
        self.assertIn("friction_run", done.stdout)

    def test_a_partial_bag_is_reported_and_offers_no_rerun(self):
        done = self.report()
        self.assertNotIn("partial", done.stdout)
        for kwargs, lacks in [({"frames_from": 23}, "the interface frames before number 23 (the start of the run)"),
                              ({"frames_lost": (40, 41, 70)}, "3 interface frames between the recorded ones"),
                              ({"events_lost": (0,)}, "the slip events before number 1")]:
            write_bag(self.bag, **kwargs)
            done = self.report()
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertIn("rig_report: warning: the bag is partial: it lacks " + lacks, done.stdout)
            self.assertNotIn("friction_run", done.stdout)

    def test_the_detectors_events_on_request(self):
        done = self.report("--events", "detector")
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual([round(float(row["shear_ratio"]), 9) for row in self.table()], [0.1001, 0.2001])

    def test_a_bag_without_the_topics_asked_for_is_refused_naming_its_topics(self):
        done = self.report("--ns", "bench")
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("holds no /bench/load_cells; its topics:", done.stderr)
        self.assertIn("/rig/load_cells", done.stderr)
        write_bag(self.bag, detector=False)  # as the simulator records it: no detector
        done = self.report("--events", "detector")
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("holds no /rig/precursor_detector/slip_events; its topics:", done.stderr)

    def test_a_missing_or_broken_bag_is_refused_in_a_sentence(self):
        for path, reason in [(os.path.join(self.work, "missing.bag"), "No such file"),
                             (os.path.join(ROOT, "README.md"), "")]:
            done = subprocess.run(["/usr/bin/python3", RIG_REPORT, path], capture_output=True, text=True, timeout=120)
            self.assertNotEqual(done.returncode, 0)
            self.assertIn("rig_report: cannot read the bag %s: %s" % (path, reason), done.stderr)
            self.assertNotIn("Traceback", done.stderr)

    def test_the_rig_is_found_in_any_namespace_or_chosen_among_several(self):
        for namespace in ["/bench", ""]:  # "": the root namespace, topics /load_cells ...
            write_bag(self.bag, namespace=namespace)
            done = self.report()
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertEqual([float(row["shear_ratio"]) for row in self.table()], [0.1, 0.2])
        write_bag(self.bag, namespace="/bench", also="/rig")
        done = self.report()
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("holds several rigs; choose one (rig_report --ns, results.load's namespace): /bench/ | /rig/",
                      done.stderr)
        done = self.report("--ns", "rig")
        self.assertEqual(done.returncode, 0, done.stderr)

    def test_a_changing_normal_load_gets_a_panel_of_its_own(self):
        # The loading curve is 3.6 inches high at 150 dpi, 5 with F_Z's panel below it.
        def figure_height():
            with open(os.path.join(self.work, "loading_curve.png"), "rb") as png:
                return struct.unpack(">II", png.read(24)[16:24])[1]  # IHDR: width, height
        def height_with(**bag):
            write_bag(self.bag, **bag)
            self.assertEqual(self.report().returncode, 0)
            return figure_height()
        self.assertEqual(height_with(commands=False), 540)
        self.assertEqual(height_with(commands=True), 750)  # a normal-load command
        self.assertEqual(height_with(commands=False, normal_load_rise=5.0), 750)  # 500 N over the run
        # A spring mattress's F_Z moves a little with the slider: 0.01 % is no change of the load.
        self.assertEqual(height_with(commands=False, normal_load_rise=0.002), 540)

    def test_figures_for_a_paper_in_every_format_asked_at_the_resolution_asked(self):
        write_bag(self.bag, commands=False, ageing=True)
        done = self.report("--format", "png", "pdf", "svg", "--dpi", "300")
        self.assertEqual(done.returncode, 0, done.stderr)
        for name in ["loading_curve", "precursors", "slip_map", "static_friction"]:
            for extension in ["png", "pdf", "svg"]:
                self.assertIn("%s.%s" % (name, extension), done.stdout.split())
                self.assertTrue(os.path.exists(os.path.join(self.work, "%s.%s" % (name, extension))))
        with open(os.path.join(self.work, "loading_curve.png"), "rb") as png:
            self.assertEqual(struct.unpack(">II", png.read(24)[16:24]), (2100, 1080))  # 7 x 3.6 inches
        with open(os.path.join(self.work, "loading_curve.pdf"), "rb") as pdf:
            self.assertEqual(pdf.read(5), b"%PDF-")
        # Titles name the scene; the maps' rows carry the simulated time.
        with open(os.path.join(self.work, "loading_curve.svg")) as svg:
            self.assertIn("synthetic: loading curve", svg.read())
        with open(os.path.join(self.work, "slip_map.svg")) as svg:
            text = svg.read()
            self.assertIn("simulated time t (s)", text)
            self.assertIn("one row per frame, not to scale", text)
            self.assertIn("0.001", text)  # the first frame's time, the top row's label
        self.assertNotEqual(self.report("--dpi", "0").returncode, 0)

    def test_an_unknown_slider_length_gives_no_length_ratio(self):
        # The detector's events on a single block without a scene carry L = 0.
        write_bag(self.bag, slider_length=0.0)
        done = self.report()
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual([row["length_ratio"] for row in self.table()], ["nan", "nan"])


def write_results_folder(folder):
    """A friction_run folder: its scene, a loading curve and four events, one of each kind the rule tells
    apart but back-slips (the columns of results.EVENT_COLUMNS, unused ones 0)."""
    os.makedirs(folder)
    with open(os.path.join(folder, "scene.yaml"), "w") as handle:
        handle.write(SCENE)
    with open(os.path.join(folder, "loading.csv"), "w") as handle:
        handle.write("time_s,stage_position_m,shear_force_N,normal_force_N,interface_normal_sum_N,sliding_nodes\n")
        for step in range(101):
            handle.write("%g,0,%g,%g,%g,0\n" % (step * 1e-3, 4.0 * step, F_Z, F_Z))
    # onset (s), F_X/F_Z, L_p (m), global: a precursor, a single-node slip, the global slip, a later one.
    events = [(0.02, 0.05, 0.03, 0), (0.04, 0.08, 0.0, 0), (0.06, 0.12, 0.14, 1), (0.09, 0.1, 0.05, 0)]
    with open(os.path.join(folder, "events.csv"), "w", newline="") as handle:
        writer = csv.DictWriter(handle, results.EVENT_COLUMNS, restval=0, lineterminator="\n")
        writer.writeheader()
        for index, (onset, ratio, length, glob) in enumerate(events):
            writer.writerow({"index": index, "onset_time_s": onset, "end_time_s": onset + 0.001, "shear_ratio": ratio,
                             "onset_shear_force_N": ratio * F_Z, "onset_normal_force_N": F_Z,
                             "rupture_length_m": length, "length_ratio": length / 0.14, "global": glob,
                             "mean_slip_m": 1e-6})


class RigReportFolderTest(unittest.TestCase):
    """A friction_run folder: the loading curve and the precursors, the events classified by the rule
    the simulator applies, and the folder's own tables left as they are."""

    def setUp(self):
        self.work = tempfile.mkdtemp(prefix="rig_report_folder_test_")
        self.addCleanup(shutil.rmtree, self.work)
        self.folder = os.path.join(self.work, "run")
        write_results_folder(self.folder)

    def report(self, *args):
        return subprocess.run(["/usr/bin/python3", RIG_REPORT, self.folder, "--format", "svg"] + list(args),
                              capture_output=True, text=True, timeout=120)

    def test_its_figures_classify_each_event_and_leave_its_tables_alone(self):
        with open(os.path.join(self.folder, "events.csv"), "rb") as handle:
            table = handle.read()
        done = self.report()
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("no slip map", done.stdout)
        self.assertFalse(os.path.exists(os.path.join(self.folder, "slip_map.svg")))
        with open(os.path.join(self.folder, "events.csv"), "rb") as handle:
            self.assertEqual(handle.read(), table)
        with open(os.path.join(self.folder, "precursors.svg")) as svg:
            text = svg.read()
        self.assertIn("synthetic: precursor length against load", text)
        for label in ["precursor (an arrested front)", "single-node slip (L_p = 0)", "global slip",
                      "arrested after a global slip"]:
            self.assertIn(label, text)
        self.assertNotIn("back-slip", text)
        with open(os.path.join(self.folder, "loading_curve.svg")) as svg:
            text = svg.read()
        self.assertIn("F_X / F_Z (F_Z = 1920 N)", text)
        # The printed table: one row per event, its L_p/L from the folder.
        rows = [line.split() for line in done.stdout.splitlines() if line.split()[:1] in (["0"], ["1"], ["2"], ["3"])]
        self.assertEqual([row[3] for row in rows], ["0.2143", "0.0000", "1.0000", "0.3571"])

    def test_an_other_out_folder_gets_copies_of_its_tables(self):
        out = os.path.join(self.work, "figures")
        done = self.report("--out", out)
        self.assertEqual(done.returncode, 0, done.stderr)
        for name in ["scene.yaml", "events.csv"]:
            with open(os.path.join(self.folder, name), "rb") as source, open(os.path.join(out, name), "rb") as copy:
                self.assertEqual(copy.read(), source.read(), name)
        self.assertTrue(os.path.exists(os.path.join(out, "loading_curve.svg")))

    def test_a_folder_without_events_is_refused_in_a_sentence(self):
        os.remove(os.path.join(self.folder, "events.csv"))
        done = self.report()
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("holds no events.csv: not a results folder", done.stderr)
        self.assertNotIn("Traceback", done.stderr)


def all_tests():
    """Both classes, in one results file."""
    loader = unittest.TestLoader()
    return unittest.TestSuite([loader.loadTestsFromTestCase(RigReportTest),
                               loader.loadTestsFromTestCase(RigReportFolderTest)])


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "rig_report", "__main__.all_tests")
