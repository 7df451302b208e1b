#!/usr/bin/python3
"""rostest: rviz loads rig.rviz with the rig's plugins while a short run plays, and draws it.

Starts rviz (the test's DISPLAY is an Xvfb screen), takes a screenshot while every node sticks and
another with the simulator paused in the middle of a slip event, and asserts: rviz printed no error
(plugin not loaded, display error, exception); the slider is drawn in the 3D view; the interface band
is blue (stuck) in the first and has red (sliding) nodes in the second, towards the trailing edge where
the slip starts. The band is found as the rows that are blue in the first screenshot, so that the red
of the stress colours and the colour bar does not count.
"""
import os
import subprocess
import sys
import tempfile
import time
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402
import numpy  # noqa: E402
import rospy  # noqa: E402
import rostest  # noqa: E402
from friction_msgs.msg import InterfaceState  # noqa: E402
from std_srvs.srv import SetBool  # noqa: E402

# The 3D view's lower part, where rig.rviz puts the slider (window 1400 x 860 at the origin).
VIEW = (slice(380, 760), slice(780, 1390))
NOISE = ("media_export", "librospack")  # Debian's rviz asks rospack for a package it does not ship


def screenshot(path):
    # PNG24: RGB even while the screen is one colour, before rviz draws (a grey PNG would have one channel).
    subprocess.run(["import", "-window", "root", "PNG24:" + path], check=True)
    image = matplotlib.image.imread(path)[..., :3]
    return image[VIEW]


def screenshot_once(path, drawn, timeout):
    """A screenshot as soon as `drawn` holds for it (or the last one at the timeout): rviz takes its
    time to start and to redraw, more on a loaded machine, and a test must not guess how long."""
    deadline = time.time() + timeout
    region = screenshot(path)
    while not drawn(region) and time.time() < deadline:
        time.sleep(0.5)
        region = screenshot(path)
    return region


def ink(region):
    return (region.sum(axis=2) < 2.4)


def slider_drawn(region):
    """The loading slider is drawn, with its interface band."""
    return ink(region).sum() > 20000 and band_rows(region).size > 0


def stuck_blue(region):
    r, g, b = region[..., 0], region[..., 1], region[..., 2]
    return (b > 0.85) & (r < 0.3) & (g < 0.5)


def band_rows(region):
    """The rows of a view that the stuck interface band crosses: more than 50 blue pixels wide."""
    return numpy.flatnonzero(stuck_blue(region).sum(axis=1) > 50)


def band_of(region, rows):
    """The interface band's rows (one row of margin) of a view; nothing if no band was found."""
    return region[max(rows.min() - 1, 0):rows.max() + 2] if rows.size else region[:0]


def sliding_nodes(frame):
    return sum(1 for s in frame.state if s == InterfaceState.SLIDING) if frame is not None else 0


def sliding_red(region):
    r, g, b = region[..., 0], region[..., 1], region[..., 2]
    return (r > 0.85) & (g < 0.3) & (b < 0.3)


class RvizScreenshot(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("rviz_screenshot_test")
        cls.out = rospy.get_param("~out", tempfile.mkdtemp(prefix="friction_rviz_test_"))
        print("screenshots in " + cls.out)
        config = rospy.get_param("~config")
        cls.log = open(os.path.join(cls.out, "rviz_output.txt"), "w+")

        def start_rviz():
            return subprocess.Popen(["rviz", "-d", config], stdout=cls.log, stderr=subprocess.STDOUT)

        cls.rviz = start_rviz()
        cls.sliding_frame = None
        cls.last_frame = None
        cls.watching = False
        # Listening from the start: the rig runs once rviz and this test listen to its camera
        # (rviz_screenshot.test), so a slow start of either misses nothing.
        rospy.Subscriber("/rig/interface", InterfaceState, cls.on_frame, queue_size=1)
        rospy.wait_for_service("/rig/pause", timeout=240)
        cls.pause = rospy.ServiceProxy("/rig/pause", SetBool, persistent=True)
        # rviz starts, loads the plugins and draws the loading slider with its interface band.
        stuck_path = os.path.join(cls.out, "stuck.png")
        cls.stuck = screenshot_once(stuck_path, slider_drawn, 120)
        if not slider_drawn(cls.stuck):
            # rviz on Xvfb's software GL can hang as it starts, before it loads a display (its output the
            # same as a good start's): started again, it draws. The rig waits for its subscribers meanwhile.
            cls.rviz.kill()
            cls.rviz.wait()
            cls.log.write("rviz_screenshot_test: nothing drawn 120 s after the start; rviz started again\n")
            cls.log.flush()
            cls.rviz = start_rviz()
            cls.stuck = screenshot_once(stuck_path, slider_drawn, 150)
        cls.band_rows = band_rows(cls.stuck)
        # Within the band's rows only: the colour bar beside the slider is blue at its bottom too.
        columns = numpy.flatnonzero(stuck_blue(cls.stuck)[cls.band_rows].any(axis=0))
        cls.band_columns = (columns.min(), columns.max()) if columns.size else (0, 0)
        # Pause the rig from the frame callback itself, while the event is still under way. On a loaded
        # machine the pause can land after the event has ended (the simulator catches up on its pace):
        # then the last frame, the one the display shows, is stuck again, and the rig runs on to the next.
        cls.watching = True
        deadline = time.time() + 240
        while time.time() < deadline:
            if cls.sliding_frame is not None:
                time.sleep(0.5)  # frames published before the pause took effect
                if sliding_nodes(cls.last_frame) >= 3:
                    break
                cls.sliding_frame = None
                cls.pause(False)
            time.sleep(0.01)
        cls.sliding = screenshot_once(os.path.join(cls.out, "sliding.png"),
                                      lambda view: sliding_red(band_of(view, cls.band_rows)).sum() > 100, 60)
        cls.pause(False)
        cls.rviz.terminate()
        cls.rviz.wait(timeout=30)
        cls.log.seek(0)
        cls.output = cls.log.read()

    @classmethod
    def on_frame(cls, msg):
        cls.last_frame = msg
        if cls.watching and cls.sliding_frame is None and sliding_nodes(msg) >= 3:
            cls.pause(True)
            cls.sliding_frame = msg

    def test_rviz_reports_no_error(self):
        bad = [line for line in self.output.splitlines()
               if any(word in line for word in ("ERROR", "Error", "could not be loaded", "xception"))
               and not any(noise in line for noise in NOISE)]
        self.assertEqual(bad, [], "rviz printed:\n" + "\n".join(bad))

    def band(self, region):
        return band_of(region, self.band_rows)

    def test_slider_is_drawn_in_the_view(self):
        self.assertGreater(int(ink(self.stuck).sum()), 20000)

    def test_interface_band_is_blue_while_stuck(self):
        # A thin horizontal band across the slider's length, blue with no red.
        self.assertGreater(len(self.band_rows), 0)
        self.assertLess(len(self.band_rows), 15, self.band_rows)
        self.assertGreater(self.band_columns[1] - self.band_columns[0], 300, self.band_columns)
        self.assertGreater(int(stuck_blue(self.band(self.stuck)).sum()), 300)
        self.assertLess(int(sliding_red(self.band(self.stuck)).sum()), 20)

    def test_interface_band_turns_red_where_it_slides(self):
        self.assertIsNotNone(self.sliding_frame)
        red = sliding_red(self.band(self.sliding))
        red_columns = numpy.flatnonzero(red.any(axis=0))
        self.assertGreater(int(red.sum()), 100)
        # The slip starts at the trailing edge (x = 0, the band's left end): so do the red nodes.
        middle = 0.5 * (self.band_columns[0] + self.band_columns[1])
        self.assertLess(red_columns.mean(), middle, (red_columns.min(), red_columns.max(), self.band_columns))


if __name__ == "__main__":
    rostest.rosrun("friction_rviz", "rviz_screenshot", RvizScreenshot, sys.argv)
