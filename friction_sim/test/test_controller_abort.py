#!/usr/bin/python3
"""The stage controller against a stand-in simulator that takes every command but cannot be unpaused:
left paused, a simulator would wait for ever with the protocol scheduled, so the controller must abort
its run, once, and say why. The stand-in offers the simulator's services and publishes its stage state;
its pause service fails."""
import threading
import time
import unittest

import rospy
import rostest
from friction_msgs.msg import StageState
from friction_msgs.srv import SendStageCommand, SendStageCommandResponse, SetRunEnd, SetRunEndResponse
from rosgraph_msgs.msg import Log
from std_srvs.srv import SetBool, Trigger, TriggerResponse

REASON = "the simulator could not be unpaused (pause failed); aborting the run"


class ControllerAbortTest(unittest.TestCase):
    def test_a_simulator_that_cannot_be_unpaused_has_its_run_aborted(self):
        lock = threading.Lock()
        calls = {"commands": 0, "pause": [], "abort": 0, "stop": 0}
        logged = []

        def on_command(_request):
            with lock:
                calls["commands"] += 1
            return SendStageCommandResponse(accepted=True, reason="")

        def on_pause(request):
            with lock:
                calls["pause"].append(request.data)
            raise rospy.ServiceException("the stand-in cannot be unpaused")

        def on_end(name):
            def handle(_request):
                with lock:
                    calls[name] += 1
                return TriggerResponse(success=True, message=name)
            return handle

        rospy.Service("send_command", SendStageCommand, on_command)
        rospy.Service("set_run_end", SetRunEnd, lambda _request: SetRunEndResponse(accepted=True, reason=""))
        rospy.Service("pause", SetBool, on_pause)
        rospy.Service("abort", Trigger, on_end("abort"))
        rospy.Service("stop", Trigger, on_end("stop"))
        rospy.Subscriber("/rosout", Log, lambda log: logged.append(log.msg) if log.name == "/rig/controller" else None,
                         queue_size=1000)
        state_topic = rospy.Publisher("stage_state", StageState, queue_size=10)
        # The paused simulator's state, again and again at t = 0, until the controller has aborted.
        state = StageState(normal_force=1920.0, paused=True)
        deadline = time.time() + 60.0
        while time.time() < deadline:
            with lock:
                if calls["abort"] > 0:
                    break
            state_topic.publish(state)
            time.sleep(0.05)
        time.sleep(1.0)  # time for a second abort or a log line to come, if any would
        with lock:
            self.assertEqual(calls["abort"], 1, calls)
            self.assertEqual(calls["stop"], 0, calls)
            self.assertEqual(calls["pause"], [False], calls)
            # two_global_events.yaml: four steps, one command each.
            self.assertEqual(calls["commands"], 4, calls)
        self.assertTrue(any(REASON in line for line in logged), logged)


if __name__ == "__main__":
    rospy.init_node("stand_in_simulator")
    rostest.rosrun("friction_sim", "controller_abort", ControllerAbortTest)
