#!/usr/bin/python3
"""contact_monitor, the Python analysis node, against the simulator's camera: one message per frame,
with the frame's stamp, whose shares are the frame's counts of stuck, sliding and lifted nodes; all
stuck at the start, and more than half of the interface sliding at once in a global event."""
import threading
import time
import unittest

import rospy
import rostest
from friction_msgs.msg import InterfaceState, SlipEvent
from geometry_msgs.msg import Vector3Stamped


class ContactMonitorTest(unittest.TestCase):
    def test_shares_follow_the_camera_frame_by_frame(self):
        lock = threading.Lock()
        # By stamp, in arrival order: a frame where a node unsticks may share its step with a regular one.
        frames, shares, global_events = {}, {}, []

        def on_frame(frame):
            with lock:
                frames.setdefault(frame.header.stamp.to_nsec(), []).append(frame.state)

        def on_shares(message):
            with lock:
                shares.setdefault(message.header.stamp.to_nsec(), []).append(message.vector)

        # The node's output first: the simulator starts once the node and this test hear its camera.
        listening = rospy.Subscriber("/rig/contact_monitor/contact_shares", Vector3Stamped, on_shares,
                                     queue_size=100000)
        deadline = time.time() + 60.0
        while listening.get_num_connections() == 0 and time.time() < deadline:
            time.sleep(0.05)
        self.assertGreater(listening.get_num_connections(), 0, "never connected to contact_monitor's shares")
        rospy.Subscriber("/rig/slip_events", SlipEvent,
                         lambda event: global_events.append(event) if event.global_event else None, queue_size=1000)
        rospy.Subscriber("/rig/interface", InterfaceState, on_frame, queue_size=100000)
        deadline = time.time() + 200.0
        while len(global_events) < 2 and time.time() < deadline:
            time.sleep(0.1)
        # The last frames' shares: the node may lag behind the simulator. Done once every frame has its
        # shares and no frame has come for a second.
        deadline = time.time() + 120.0
        seen, quiet_since = -1, time.time()
        while time.time() < deadline:
            with lock:
                count = sum(len(states) for states in frames.values())
                caught_up = sorted(shares) == sorted(frames) and all(len(shares[t]) == len(f)
                                                                     for t, f in frames.items())
            if count != seen:
                seen, quiet_since = count, time.time()
            elif caught_up and time.time() - quiet_since > 1.0:
                break
            time.sleep(0.1)
        self.assertEqual(len(global_events), 2)
        with lock:
            self.assertGreater(sum(len(states) for states in frames.values()), 100)
            self.assertEqual(sorted(shares), sorted(frames))
            for stamp, states in frames.items():
                self.assertEqual(len(shares[stamp]), len(states))
                for state, vector in zip(states, shares[stamp]):
                    nodes = len(state)
                    self.assertEqual((vector.x, vector.y, vector.z),
                                     (state.count(0) / nodes, state.count(1) / nodes, state.count(2) / nodes))
            first = shares[min(shares)][0]
            self.assertEqual((first.x, first.y, first.z), (1.0, 0.0, 0.0))
            self.assertGreater(max(vector.y for vectors in shares.values() for vector in vectors), 0.5)


if __name__ == "__main__":
    rospy.init_node("test_contact_monitor")
    rostest.rosrun("friction_sim", "contact_monitor", ContactMonitorTest)
