#!/usr/bin/python3
"""scripts/rig_launch.sh's exit status: roslaunch itself exits 0 when a node refuses its input or
crashes, so the script reads the nodes' exit codes and fails, naming the node; a run that ends cleanly
exits 0, an interrupted one 130 after every node has stopped. Each launch brings up its own private
master on a free port. It keeps the caller's packages (a launch file of their own, by package name,
with a node of their own) and writes no terminal codes into a pipe."""
import json
import os
import re
import resource
import shutil
import signal
import statistics
import subprocess
import tempfile
import threading
import time
import unittest

import rosunit

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RIG_LAUNCH = os.path.join(ROOT, "scripts/rig_launch.sh")
RIG = os.path.join(ROOT, "launch/rig.launch")
SINGLE_BLOCK = os.path.join(ROOT, "friction_sim/scenes/single_block.yaml")


def parent_pids():
    """pid -> parent pid of every process."""
    parents = {}
    for entry in os.listdir("/proc"):
        try:
            with open("/proc/%s/stat" % entry) as stat:
                parents[int(entry)] = int(stat.read().rsplit(")", 1)[1].split()[1])
        except (ValueError, OSError):
            continue
    return parents


def descendant_named(root, name):
    """The pid of a process called `name` below `root`, or None."""
    parents = parent_pids()
    for pid in parents:
        ancestor = parents.get(pid)
        while ancestor and ancestor != root:
            ancestor = parents.get(ancestor)
        if ancestor == root:
            try:
                with open("/proc/%d/comm" % pid) as comm:
                    if comm.read().strip() == name:
                        return pid
            except OSError:
                continue
    return None


class SlowRun:
    """The default experiment at a hundredth of real time (or the launch with `args`), with its
    simulator's pid once its run is under way: once the controller has said that its protocol started."""

    STARTED = "stage controller: protocol started"

    def __init__(self, *args):
        self.args = list(args) or ["real_time_factor:=0.01"]

    def __enter__(self):
        self.process = subprocess.Popen([RIG_LAUNCH, RIG] + self.args, stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, text=True)
        self.lines = []
        self.started = threading.Event()
        self.reader = threading.Thread(target=self.read, daemon=True)
        self.reader.start()
        self.started.wait(timeout=240)
        self.simulator = descendant_named(self.process.pid, "rig_simulator") if self.started.is_set() else None
        return self

    def read(self):
        for line in self.process.stdout:
            self.lines.append(line)
            if self.STARTED in line:
                self.started.set()

    def finish(self):
        self.process.wait(timeout=120)
        self.reader.join(timeout=10)
        return self.process.returncode, "".join(self.lines)

    def __exit__(self, *exc):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        self.reader.join(timeout=10)
        self.process.stdout.close()


def master_uri(first_line):
    """The private master's address, from the first line rig_launch.sh prints."""
    return re.search(r"private master at (\S+);", first_line).group(1)


def client(lines, command):
    """`command` run in the rig's network, as the lines rig_launch.sh printed first say to reach it: through
    the namespace's entry where it has one."""
    entry = re.search(r"^  (nsenter .*) bash   \(the rig's own network", "".join(lines[:3]), re.MULTILINE)
    return (entry.group(1).split() if entry else []) + command


def tcp_sockets(net_directory):
    """The fields of every TCP socket of a network namespace, from its /proc/<pid>/net: the local address
    (hex, as the kernel writes it) at 1, the state at 3, tx_queue:rx_queue (hex) at 4, the inode at 9."""
    for table in ("tcp", "tcp6"):
        with open(os.path.join(net_directory, table)) as handle:
            yield from (row.split() for row in list(handle)[1:])


def listening(net_directory):
    """The local address of every listening TCP socket of a network namespace (tcp_sockets)."""
    return [fields[1] for fields in tcp_sockets(net_directory) if fields[3] == "0A"]


def received_unread(pid):
    """Bytes that have reached the TCP sockets of process `pid` and that it has not read yet."""
    inodes = set()
    for fd in os.listdir("/proc/%d/fd" % pid):
        try:
            target = os.readlink("/proc/%d/fd/%s" % (pid, fd))
        except OSError:
            continue
        socket = re.fullmatch(r"socket:\[(\d+)\]", target)
        if socket:
            inodes.add(socket.group(1))
    return sum(int(fields[4].split(":")[1], 16) for fields in tcp_sockets("/proc/%d/net" % pid)
               if fields[9] in inodes)


def settled(read, quiet=0.5, timeout=120):
    """read()'s value once it is above zero and has not changed for `quiet` s (0 if it never is)."""
    last, still_since = read(), time.monotonic()
    deadline = still_since + timeout
    while time.monotonic() < deadline:
        time.sleep(0.05)
        value = read()
        if value != last:
            last, still_since = value, time.monotonic()
        elif value > 0 and time.monotonic() - still_since >= quiet:
            return value
    return 0


def launch(*args, cwd=None, env=None, launch_file=(RIG,)):
    done = subprocess.run([RIG_LAUNCH] + list(launch_file) + list(args), capture_output=True, text=True, timeout=120,
                          cwd=cwd, env=env)
    return done.returncode, done.stdout + done.stderr


# Publishes 5000 commands on the rig's topic as fast as it can once told to (a line on its input), after
# saying that the simulator listens; then gives them 5 s to drain (waits in wall time: the rig's clock
# runs at a hundredth of it).
FLOOD = """
import sys
import time
import rospy
from friction_msgs.msg import StageCommand
rospy.init_node("flood", anonymous=True)
publisher = rospy.Publisher("/rig/stage_command", StageCommand, queue_size=100000)
while publisher.get_num_connections() == 0:
    time.sleep(0.05)
print("connected", flush=True)
sys.stdin.readline()
for _ in range(5000):
    publisher.publish(StageCommand(mode=StageCommand.HOLD))
print("sent", flush=True)
time.sleep(5.0)
"""

# For 4 s of wall time: when each load-cell message arrives, and how long the pause service takes to
# answer (asked to keep running), printed as JSON.
PACING = """
import json
import time
import rospy
from geometry_msgs.msg import WrenchStamped
from std_srvs.srv import SetBool
rospy.init_node("pacing", anonymous=True)
arrivals = []
rospy.Subscriber("/rig/load_cells", WrenchStamped, lambda _: arrivals.append(time.time()), queue_size=100000)
rospy.wait_for_service("/rig/pause", timeout=60)
keep_running = rospy.ServiceProxy("/rig/pause", SetBool)
time.sleep(1.0)
start = time.time()
del arrivals[:]
latencies = []
while time.time() - start < 4.0:
    asked = time.time()
    keep_running(False)
    latencies.append(time.time() - asked)
    time.sleep(0.2)
print(json.dumps({"start": start, "arrivals": list(arrivals), "latencies": latencies}))
"""

# Asks the simulator, through dynamic_reconfigure, for a bad gauge rate, then for twice the pace and half
# the load-cell rate, and notes the load cells' stamps for 2 s of wall time a second after the change;
# then for a negative pace, then for no pace, and notes the simulated time the load cells reach 3 s
# later. Printed as JSON with the configurations the simulator answered.
RECONFIGURE = """
import json
import time
import rospy
from dynamic_reconfigure.client import Client
from geometry_msgs.msg import WrenchStamped
rospy.init_node("reconfigure", anonymous=True)
arrivals = []
rospy.Subscriber("/rig/load_cells", WrenchStamped, lambda m: arrivals.append(m.header.stamp.to_sec()),
                 queue_size=100000)
client = Client("/rig/simulator", timeout=60)
refused = client.update_configuration({"gauge_rate": 0.0})
changed = client.update_configuration({"real_time_factor": 0.02, "load_cell_rate": 5000.0})
time.sleep(1.0)
del arrivals[:]
time.sleep(2.0)
stamps = list(arrivals)
negative = client.update_configuration({"real_time_factor": -1.0})
client.update_configuration({"real_time_factor": 0.0})
unpaced_from = arrivals[-1]
time.sleep(3.0)
print(json.dumps({"refused": refused, "changed": changed, "stamps": stamps, "negative": negative,
                  "unpaced_from": unpaced_from, "unpaced_to": arrivals[-1]}))
"""

USERS_LAUNCH = """<launch>
  <include file="$(find friction_sim)/launch/rig.launch">
    <arg name="scene" value="%s"/>
    <arg name="controller" value="false"/>
    <arg name="analysis" value="false"/>
  </include>
  <node pkg="users_analysis" type="mark_run" name="mark_run"/>
</launch>
"""


class RigLaunchStatusTest(unittest.TestCase):
    def work_folder(self):
        """A folder of the test's own, removed after it."""
        work = tempfile.mkdtemp(prefix="rig_launch_test_")
        self.addCleanup(shutil.rmtree, work)
        return work

    def assert_launch_fails(self, args, *said):
        """The launch with `args` (and no detector) exits 1 and its output holds each of `said`."""
        status, output = launch(*args, "analysis:=false")
        self.assertEqual(status, 1, output)
        for text in said:
            self.assertIn(text, output)
        return output

    def test_the_rig_listens_on_no_network_of_the_machine(self):
        # roscpp's servers listen on every interface of their network: the rig's network namespace holds
        # only loopback, and none of them listens in the machine's. Where the system gives no namespace,
        # the launch says so.
        machine_before = set(listening("/proc/self/net"))
        with SlowRun() as run:
            self.assertIsNotNone(run.simulator, "the simulator did not start")
            rig = "/proc/%d/net" % run.simulator
            with open(os.path.join(rig, "dev")) as devices:
                interfaces = [line.split(":")[0].strip() for line in list(devices)[2:]]
            in_rig = listening(rig)
            in_machine = set(listening("/proc/self/net"))
            namespaced = os.stat("/proc/%d/ns/net" % run.simulator).st_ino != os.stat("/proc/self/ns/net").st_ino
            run.process.send_signal(signal.SIGTERM)
            status, output = run.finish()
        self.assertEqual(status, 130, output)
        if not namespaced:
            self.assertIn("WARNING: this system gives no private network namespace", output)
            return
        self.assertEqual(interfaces, ["lo"])
        # The master, rosout, the simulator, the controller and the detector: an XML-RPC server each, and
        # a TCPROS server per node.
        self.assertGreaterEqual(len(in_rig), 5, in_rig)
        self.assertFalse(in_machine - machine_before, "new listening sockets in the machine's network")
        self.assertIn("nsenter --target %d --user --net --preserve-credentials bash" % run.process.pid, output)

    def test_the_machines_network_is_a_choice_said_aloud_and_a_bad_choice_is_refused(self):
        env = dict(os.environ, FRICTION_RIG_NETWORK="host")
        status, output = launch("scene:=" + SINGLE_BLOCK, "controller:=false", "analysis:=false", env=env)
        self.assertEqual(status, 0, output)
        self.assertIn("rig_launch: FRICTION_RIG_NETWORK=host: the rig's nodes listen on every network interface",
                      output)
        self.assertNotIn("nsenter", output)
        self.assertIn("reached 3 global slip event(s)", output)
        status, output = launch(env=dict(os.environ, FRICTION_RIG_NETWORK="public"))
        self.assertEqual(status, 2, output)
        self.assertIn("FRICTION_RIG_NETWORK: value 'public' is not allowed; allowed: private, host", output)
        # A system that refuses the namespace (here an unshare that always fails): the run goes on, warned.
        work = self.work_folder()
        with open(os.path.join(work, "unshare"), "w") as refusing:
            refusing.write("#!/bin/sh\nexit 1\n")
        os.chmod(os.path.join(work, "unshare"), 0o755)
        env = dict(os.environ, PATH=work + os.pathsep + os.environ["PATH"])
        status, output = launch("scene:=" + SINGLE_BLOCK, "controller:=false", "analysis:=false", env=env)
        self.assertEqual(status, 0, output)
        self.assertIn("loopback_only: WARNING: this system gives no private network namespace", output)
        self.assertIn("reached 3 global slip event(s)", output)

    def test_a_refused_scene_fails_the_launch_and_names_the_simulator(self):
        self.assert_launch_fails(["overrides:=pusher.height=1"], "/rig/simulator: scene refused",
                                 "pusher.height: value 1 is not allowed",
                                 "rig_launch: failed: rig_simulator (exit code 2)")

    def test_a_refused_protocol_fails_the_launch_and_names_the_controller(self):
        # The controller aborts the simulator's run: the simulator's own status tells, whatever the
        # order in which roslaunch sees the two nodes end.
        self.assert_launch_fails(["protocol:=/nonexistent/protocol.yaml"], "/rig/controller: protocol refused",
                                 "rig_simulator (exit code 4)", "aborted by the abort service")

    def test_a_bag_that_cannot_be_written_is_refused_before_the_run(self):
        output = self.assert_launch_fails(["record:=true", "bag:=/nonexistent/dir/run.bag"],
                                          "~bag: value '/nonexistent/dir/run.bag' cannot be written",
                                          "rig_launch: failed: rig_simulator (exit code 2)")
        self.assertNotIn("slip events:", output)

    def test_a_crashed_simulator_fails_the_launch(self):
        with SlowRun() as run:
            self.assertIsNotNone(run.simulator, "the simulator did not start")
            os.kill(run.simulator, signal.SIGSEGV)
            status, output = run.finish()
        self.assertEqual(status, 1, output)
        self.assertIn("rig_launch: failed: rig_simulator (exit code -11)", output)

    def test_an_interrupted_launch_stops_every_node_and_exits_130(self):
        with SlowRun() as run:
            self.assertIsNotNone(run.simulator, "the simulator did not start")
            run.process.send_signal(signal.SIGTERM)
            status, output = run.finish()
        self.assertEqual(status, 130, output)
        self.assertIn("rig_launch: interrupted", output)
        # The simulator ended its run and wrote its summary: roslaunch stopped it, not the kill.
        self.assertIn("interrupted by a signal", output)
        self.assertFalse(os.path.exists("/proc/%d" % run.simulator), "the simulator outlived the launch")

    def test_a_stage_held_without_end_runs_on_and_stops_when_interrupted(self):
        # Unpaced, a held stage with nothing due and no end time jumped to t = inf, and the simulator
        # published forever without hearing the signal.
        work = self.work_folder()
        protocol = os.path.join(work, "held.yaml")
        with open(protocol, "w") as handle:
            handle.write("steps:\n  - {action: hold, duration: .inf}\nend: {global_events: 1}\n")
        with SlowRun("protocol:=" + protocol, "analysis:=false") as run:
            self.assertIsNotNone(run.simulator, "the simulator did not start")
            threading.Event().wait(2.0)
            run.process.send_signal(signal.SIGTERM)
            status, output = run.finish()
        self.assertEqual(status, 130, output)
        self.assertIn("interrupted by a signal", output)
        self.assertRegex(output, r"simulated [0-9.e+-]+ s in [0-9]+ steps")

    def test_a_run_that_reaches_its_stop_condition_succeeds_with_paths_relative_to_the_users_directory(self):
        # The single block slips at µ_s·F_Z = 0.4 × 1920 N three times and stops (its scene's stop). The
        # nodes run elsewhere ($ROS_HOME): the scene and the bag are where the user's relative paths say.
        work = self.work_folder()
        status, output = launch("scene:=" + os.path.relpath(SINGLE_BLOCK, work), "record:=true", "bag:=run.bag",
                                "controller:=false", "analysis:=false", cwd=work)
        self.assertEqual(status, 0, output)
        self.assertTrue(os.path.exists(os.path.join(work, "run.bag")), output)
        self.assertIn("reached 3 global slip event(s)", output)
        self.assertRegex(output, r"mu_s,macro = F_X/F_Z at the first global event: 0\.4\n")
        self.assertNotIn("rig_launch: failed", output)
        # Into a pipe: no colour codes, no terminal title.
        self.assertNotIn("\x1b", output)

    def test_a_second_rig_cannot_write_the_bag_a_rig_is_writing(self):
        work = self.work_folder()
        bag = os.path.join(work, "run.bag")
        with SlowRun("real_time_factor:=0.01", "record:=true", "bag:=" + bag) as first:
            self.assertIsNotNone(first.simulator, "the simulator did not start")
            self.assertTrue(os.path.exists(bag + ".active"))  # written under a temporary name
            self.assertFalse(os.path.exists(bag))
            self.assert_launch_fails(["record:=true", "bag:=" + bag],
                                     "~bag: value '%s' is being written by another rig" % bag,
                                     "rig_launch: failed: rig_simulator (exit code 2)")
            first.process.send_signal(signal.SIGTERM)
            status, output = first.finish()
        self.assertEqual(status, 130, output)
        # Closed, it has its own name.
        self.assertTrue(os.path.exists(bag), output)
        self.assertFalse(os.path.exists(bag + ".active"))

    def test_commands_a_full_queue_drops_are_counted_and_reported(self):
        # 5000 commands reach a simulator held stopped (SIGSTOP): once it goes on, its network thread
        # queues them faster than it reads them, and its queue of 1000 overflows.
        with SlowRun() as run:
            self.assertIsNotNone(run.simulator, "the simulator did not start")
            master = master_uri(run.lines[0])
            env = dict(os.environ, ROS_MASTER_URI=master)
            flood = subprocess.Popen(client(run.lines, ["/usr/bin/python3", "-c", FLOOD]), env=env,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
            self.assertEqual(flood.stdout.readline().strip(), "connected")
            os.kill(run.simulator, signal.SIGSTOP)
            flood.stdin.write("go\n")
            flood.stdin.flush()
            self.assertEqual(flood.stdout.readline().strip(), "sent")
            # "sent" means queued in rospy; its writer thread fills the stopped simulator's socket. Once
            # nothing more arrives there, all that fits has come: resumed, its network thread reads it
            # faster than the queue is served.
            self.assertGreater(settled(lambda: received_unread(run.simulator)), 0)
            os.kill(run.simulator, signal.SIGCONT)
            flood.communicate(timeout=60)
            state = subprocess.run(client(run.lines, ["rostopic", "echo", "-n", "1",
                                                      "/rig/stage_state/commands_dropped"]),
                                   capture_output=True, text=True, timeout=60, env=env)
            run.process.send_signal(signal.SIGTERM)
            status, output = run.finish()
        dropped = int(state.stdout.split()[0])
        self.assertGreater(dropped, 0, output)
        self.assertLess(dropped, 5000)
        self.assertRegex(output, r"command\(s\) from /flood_\w+ on /rig/stage_command were dropped unread: the "
                                 r"queue of 1000 was full \(%d so far\)" % dropped)

    def measured_beside_a_slow_run(self, script):
        """What `script` printed last (JSON), run in the rig's network beside the default experiment at a
        hundredth of real time, and the rig's output."""
        with SlowRun() as run:
            self.assertIsNotNone(run.simulator, "the simulator did not start")
            master = master_uri(run.lines[0])
            measured = subprocess.run(client(run.lines, ["/usr/bin/python3", "-c", script]), capture_output=True,
                                      text=True, timeout=120, env=dict(os.environ, ROS_MASTER_URI=master))
            run.process.send_signal(signal.SIGTERM)
            _, output = run.finish()
        self.assertEqual(measured.returncode, 0, measured.stderr)
        return json.loads(measured.stdout.strip().splitlines()[-1]), output

    def test_a_paced_run_publishes_evenly_and_answers_services_at_once(self):
        # At a hundredth of real time the load cells' 10 kHz of simulated time is 100 Hz of wall time;
        # the run fast-forwards in jumps of 10 ms (a second of wall time), which came out in bursts.
        seen, _ = self.measured_beside_a_slow_run(PACING)
        # Each half second holds 50 messages, within 20 %.
        counts = [sum(1 for t in seen["arrivals"] if seen["start"] + 0.5 * k <= t < seen["start"] + 0.5 * (k + 1))
                  for k in range(8)]
        for count in counts:
            self.assertTrue(40 <= count <= 60, counts)
        self.assertLess(max(seen["latencies"]), 0.2, seen["latencies"])

    def test_the_pace_and_the_rates_change_live_and_a_bad_change_is_refused(self):
        seen, output = self.measured_beside_a_slow_run(RECONFIGURE)
        # A gauge rate of 0 is refused as the parameter would be, and the settings stay.
        self.assertEqual(seen["refused"]["gauge_rate"], 1e5)
        self.assertIn("reconfigure refused, settings kept: ~gauge_rate: value 0", output)
        self.assertEqual((seen["changed"]["real_time_factor"], seen["changed"]["load_cell_rate"]), (0.02, 5000.0))
        # 5 kHz of simulated time at a fiftieth of real time: 100 messages per second of wall time, within
        # 20 %, each 0.2 ms of simulated time after the last (events add a sample off the grid; the stamps
        # are rounded to whole nanoseconds).
        self.assertTrue(160 <= len(seen["stamps"]) <= 240, len(seen["stamps"]))
        self.assertAlmostEqual(statistics.median(b - a for a, b in zip(seen["stamps"], seen["stamps"][1:])), 2e-4,
                               delta=1e-8)
        # A negative pace is refused naming the value given (not clamped to 0 on the way), and the pace kept.
        self.assertEqual(seen["negative"]["real_time_factor"], 0.02)
        self.assertIn("reconfigure refused, settings kept: ~real_time_factor: value -1", output)
        # No pace: the run goes on as fast as it can, far beyond the 0.06 s of simulated time that 3 s of
        # wall time at 0.02 would give (the default experiment ends at 0.84 s).
        self.assertGreater(seen["unpaced_to"] - seen["unpaced_from"], 0.3)

    def test_a_simulator_told_to_wait_for_subscribers_that_never_come_fails_naming_them(self):
        self.assert_launch_fails(["scene:=" + SINGLE_BLOCK, "controller:=false", "wait_for_subscribers:=load_cells",
                                  "subscriber_timeout:=1"],
                                 "still waiting for subscribers of /rig/load_cells (0 of 1)",
                                 "rig_launch: failed: rig_simulator (exit code 5)")
        self.assert_launch_fails(["wait_for_subscribers:=load_cells:0 camera"],
                                 "~wait_for_subscribers: item 'load_cells:0' is not allowed",
                                 "~wait_for_subscribers: item 'camera' is not allowed",
                                 "rig_launch: failed: rig_simulator (exit code 2)")

    def test_a_simulator_waiting_for_subscribers_stops_when_asked(self):
        process = subprocess.Popen([RIG_LAUNCH, RIG, "scene:=" + SINGLE_BLOCK, "controller:=false", "analysis:=false",
                                    "wait_for_subscribers:=load_cells", "subscriber_timeout:=240"],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.addCleanup(lambda: process.poll() is None and process.kill())
        first_lines = [process.stdout.readline() for _ in range(3)]
        master = master_uri(first_lines[0])
        deadline = time.monotonic() + 120
        while True:  # until the master is up (rosservice waits for the service, not for the master)
            stop = subprocess.run(client(first_lines, ["rosservice", "call", "--wait", "/rig/stop"]),
                                  capture_output=True, text=True, timeout=60, env=dict(os.environ, ROS_MASTER_URI=master))
            if stop.returncode == 0 or time.monotonic() > deadline:
                break
            time.sleep(0.2)
        # Answered at once, well before the 240 s the simulator would otherwise wait.
        output = process.communicate(timeout=60)[0]
        self.assertIn("stopping at t = 0", stop.stdout, stop.stderr)
        self.assertEqual(process.returncode, 0, output)
        self.assertIn("stopped by the stop service at t = 0 s", output)
        self.assertNotIn("still waiting", output)

    def test_a_bag_that_cannot_be_written_further_ends_the_run_keeping_what_was_written(self):
        # Past a file size limit of 1 MiB the bag's writes fail, as on a full disk.
        work = self.work_folder()
        bag = os.path.join(work, "run.bag")
        limit = 1 << 20
        done = subprocess.run([RIG_LAUNCH, RIG, "record:=true", "bag:=" + bag, "analysis:=false"],
                              capture_output=True, text=True, timeout=240,
                              preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit)))
        output = done.stdout + done.stderr
        self.assertEqual(done.returncode, 1, output)
        self.assertIn("rig_launch: failed: rig_simulator (exit code 3)", output)
        self.assertRegex(output, r"the bag could not be written \(.*\): the run ends at t = ")
        self.assertNotIn("reached 4 global slip event(s)", output)
        # Its index could not be written either: it stays under its temporary name, and rosbag reindex
        # recovers the messages written.
        active = bag + ".active"
        self.assertIn("rosbag reindex " + active, output)
        reindexed = subprocess.run(["rosbag", "reindex", "--output-dir", work, active], capture_output=True, text=True,
                                   timeout=120)
        self.assertEqual(reindexed.returncode, 0, reindexed.stdout + reindexed.stderr)
        info = subprocess.run(["rosbag", "info", "--yaml", "--key", "topics", os.path.join(work, "run.bag.active")],
                              capture_output=True, text=True, timeout=60)
        self.assertIn("/rig/load_cells", info.stdout, info.stderr)

    def test_a_subscriber_that_comes_late_sees_the_run_from_its_first_frame(self):
        process = subprocess.Popen([RIG_LAUNCH, RIG, "scene:=" + SINGLE_BLOCK, "controller:=false", "analysis:=false",
                                    "wait_for_subscribers:=interface", "subscriber_timeout:=240"],
                                   stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)
        self.addCleanup(lambda: process.poll() is None and process.kill())
        first_lines = [process.stdout.readline() for _ in range(3)]
        master = master_uri(first_lines[0])
        threading.Event().wait(3.0)  # the rig is up and waits; a recorder started late
        seen = subprocess.run(client(first_lines, ["rostopic", "echo", "-n", "1", "/rig/interface/frame_index"]),
                              capture_output=True, text=True, timeout=60, env=dict(os.environ, ROS_MASTER_URI=master))
        output = process.communicate(timeout=120)[0]
        self.assertEqual(process.returncode, 0, output)
        self.assertEqual(seen.stdout.split(), ["0", "---"], seen.stderr)
        self.assertIn("reached 3 global slip event(s)", output)

    def test_a_users_package_launches_the_rig_by_package_name_and_its_own_node(self):
        # A package of the user's, listed by hand on ROS_PACKAGE_PATH: its launch file includes the rig's
        # by package name and starts a node of its own, which marks that it ran.
        work = self.work_folder()
        package = os.path.join(work, "users_analysis")
        os.makedirs(os.path.join(package, "launch"))
        with open(os.path.join(package, "package.xml"), "w") as handle:
            handle.write('<package format="2"><name>users_analysis</name><version>0.0.0</version>'
                         '<description>test</description><maintainer email="a@b.c">a</maintainer>'
                         '<license>BSD</license></package>\n')
        with open(os.path.join(package, "launch/users.launch"), "w") as handle:
            handle.write(USERS_LAUNCH % SINGLE_BLOCK)
        marker = os.path.join(package, "mark_run")
        with open(marker, "w") as handle:
            handle.write('#!/bin/sh\ntouch "$(dirname "$0")/ran"\n')
        os.chmod(marker, 0o755)
        env = dict(os.environ, ROS_PACKAGE_PATH=package + os.pathsep + os.environ.get("ROS_PACKAGE_PATH", ""))
        status, output = launch(env=env, launch_file=("users_analysis", "users.launch"))
        self.assertEqual(status, 0, output)
        self.assertIn("reached 3 global slip event(s)", output)
        self.assertTrue(os.path.exists(os.path.join(package, "ran")), output)


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "rig_launch_status", RigLaunchStatusTest)
