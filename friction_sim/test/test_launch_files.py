#!/usr/bin/python3
"""The launch files as roslaunch reads them, without starting anything: rviz follows the rig's namespace
(rig.rviz names /rig's topics and services, remapped to the rig's), and multi_machine.launch runs the
simulator on the compute host and everything else, rviz included, on the workstation, with every
argument of rig.launch passed on; and every default of the simulator's live settings that the launch
files, its header and ros_api.md state is its own."""
import os
import re
import unittest
from xml.etree import ElementTree

import roslaunch.config
import roslaunch.rlutil
import rosunit
from friction_sim.cfg import SimulatorConfig

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LAUNCH = os.path.join(ROOT, "launch")
RIG_RVIZ = os.path.join(ROOT, "friction_rviz/config/rig.rviz")
RIG_PANEL = os.path.join(ROOT, "friction_rviz/src/rig_panel.cpp")


def load(launch_file, *args):
    # Machines are not assigned: that would resolve the compute host's address.
    return roslaunch.config.load_config_default([(os.path.join(LAUNCH, launch_file), list(args))], None,
                                                assign_machines=False)


def arguments(launch_file):
    """A launch file's XML root: its <arg> declarations as written, defaults and docs unresolved."""
    return ElementTree.parse(os.path.join(LAUNCH, launch_file)).getroot()


def simulator_defaults_stated(pairs):
    """{setting: value} of the (name, number as text) pairs that name one of the simulator's live settings."""
    return {name: float(text) for name, text in pairs if name in SimulatorConfig.defaults}


def host(config, name):
    """The address of the machine that runs node `name` ('' = this one, with no machine declared)."""
    machine = node(config, name).machine_name
    return config.machines[machine].address if machine else ""


def node(config, name):
    matches = [n for n in config.nodes if n.name == name]
    assert len(matches) == 1, "%s: %d nodes named %s" % (config, len(matches), name)
    return matches[0]


def names_in_rig_rviz():
    """The absolute topic names of rig.rviz's displays and the names its panel reaches in its namespace."""
    with open(RIG_RVIZ) as config:
        text = config.read()
    topics = re.findall(r"^\s*Topic: (\S+)", text, re.M)
    namespace = re.search(r"^\s*Namespace: (\S+)", text, re.M).group(1)
    with open(RIG_PANEL) as source:
        # The panel's subscriptions and service clients, read from its source: a new one is checked too.
        panel = re.findall(r"rig\.(?:subscribe|serviceClient<[^>]+>)\(\s*\"(\w+)\"", source.read())
    assert len(panel) >= 5, panel
    return topics + [namespace + "/" + name for name in panel]


class LaunchFilesTest(unittest.TestCase):
    def test_every_launch_file_is_found_by_package_name(self):
        for name in sorted(os.listdir(LAUNCH)):
            resolved = roslaunch.rlutil.resolve_launch_arguments(["friction_sim", name])
            self.assertEqual(os.path.realpath(resolved[0]), os.path.join(os.path.realpath(LAUNCH), name))

    def check_rviz_follows(self, config, namespace):
        remaps = dict(node(config, "rviz").remap_args)
        for name in names_in_rig_rviz():
            self.assertTrue(name.startswith("/rig/"), name)
            self.assertEqual(remaps.get(name), "/%s/%s" % (namespace, name[len("/rig/"):]), name)

    def test_rviz_follows_the_rigs_namespace_live_and_in_playback(self):
        self.check_rviz_follows(load("rig.launch", "ns:=bench2", "rviz:=true"), "bench2")
        self.check_rviz_follows(load("rig.launch", "rviz:=true"), "rig")
        self.check_rviz_follows(load("playback.launch", "bag:=/tmp/run.bag", "ns:=replay", "rviz:=true"), "replay")

    def test_two_recording_rigs_write_two_bags_by_default(self):
        for launch_file in ["rig.launch", "multi_machine.launch"]:
            args = ["record:=true"] + (["compute_host:=hpc1", "compute_env:=/x"] if "multi" in launch_file else [])
            first, second = (load(launch_file, *args).params["/rig/simulator/bag"].value for _ in range(2))
            self.assertTrue(first.startswith("/tmp/friction_rig") and first.endswith(".bag"), first)
            self.assertNotEqual(first, second, launch_file)

    def test_multi_machine_runs_the_simulator_remotely_with_every_rig_argument(self):
        config = load("multi_machine.launch", "compute_host:=hpc1", "compute_env:=/opt/rig/scripts/ros_env_loader.sh",
                      "overrides:=pusher.height=0.01", "record:=true", "bag:=/scratch/run.bag",
                      "real_time_factor:=0.5", "ns:=bench", "threads:=2")
        self.assertEqual(host(config, "simulator"), "hpc1")
        self.assertEqual(config.params["/bench/simulator/threads"].value, 2)
        self.assertEqual(node(config, "simulator").namespace, "/bench/")
        for workstation_node in ["controller", "precursor_detector", "rviz"]:
            self.assertEqual(host(config, workstation_node), "localhost", workstation_node)
        self.assertEqual(config.params["/bench/simulator/overrides"].value, "pusher.height=0.01")
        self.assertEqual(config.params["/bench/simulator/bag"].value, "/scratch/run.bag")
        self.assertEqual(config.params["/bench/simulator/real_time_factor"].value, 0.5)
        self.check_rviz_follows(config, "bench")
        # The rig's other arguments reach it too: without controller and analysis, the simulator alone.
        alone = load("multi_machine.launch", "compute_host:=hpc1", "compute_env:=/x", "controller:=false",
                     "analysis:=false", "rviz:=false", "required:=false")
        self.assertEqual(sorted(n.name for n in alone.nodes), ["simulator"])
        self.assertFalse(node(alone, "simulator").required)
        self.assertEqual(config.params["/bench/simulator/start_paused"].value, True)
        self.assertEqual(alone.params["/rig/simulator/start_paused"].value, False)

    def test_multi_machine_declares_and_passes_on_every_argument_of_the_rig(self):
        rig = {arg.get("name"): arg for arg in arguments("rig.launch").findall("arg")}
        del rig["simulator_machine"]
        multi = arguments("multi_machine.launch")
        declared = {arg.get("name"): arg for arg in multi.findall("arg")}
        passed = {arg.get("name"): arg.get("value") for arg in multi.find("include").findall("arg")}
        for name, arg in rig.items():
            self.assertIn(name, declared)
            self.assertEqual(passed.get(name), "$(arg %s)" % name, name)
            # The same defaults, but for rviz, which the workstation opens by default.
            if name != "rviz":
                self.assertEqual(declared[name].get("default"), arg.get("default"), name)

    def test_the_simulators_header_and_ros_api_state_its_own_defaults(self):
        # The header's parameter block and ros_api.md's table repeat the defaults for the reader: each
        # must be the simulator's (cfg/Simulator.cfg, checked against the node's options in test_conversions).
        for path, pattern in (("friction_sim/include/friction_sim/ros/rig_simulator.h",
                               r"^//\s+(\w+) \(double, ([^)]+)\)"),
                              ("docs/ros_api.md", r"^\| `(\w+)` \| double, ([^ |]+) \|")):
            with open(os.path.join(ROOT, path)) as handle:
                pairs = re.findall(pattern, handle.read(), re.MULTILINE)
            self.assertEqual(simulator_defaults_stated(pairs), SimulatorConfig.defaults, path)

    def test_the_launch_files_state_the_simulators_own_defaults(self):
        # An argument left '' leaves the simulator its default, which each doc names: the number must be
        # the simulator's (cfg/Simulator.cfg, itself checked against the node's options in test_conversions).
        for launch_file in ("rig.launch", "multi_machine.launch"):
            pairs = []
            for arg in arguments(launch_file).findall("arg"):
                said = re.search(r"\((?:simulator )?default ([^)]+)\)", arg.get("doc", ""))
                if said:
                    pairs.append((arg.get("name"), said.group(1)))
                    if arg.get("name") in SimulatorConfig.defaults:
                        self.assertEqual(arg.get("default"), "", arg.get("name"))
            self.assertEqual(simulator_defaults_stated(pairs), SimulatorConfig.defaults, launch_file)

    def test_the_simulator_waits_for_the_subscribers_it_is_given(self):
        config = load("rig.launch", "wait_for_subscribers:=load_cells interface:2", "subscriber_timeout:=5")
        self.assertEqual(config.params["/rig/simulator/wait_for_subscribers"].value, "load_cells interface:2")
        self.assertEqual(config.params["/rig/simulator/subscriber_timeout"].value, 5)

    def test_publish_rates_are_launch_arguments_and_the_simulators_defaults_stay_otherwise(self):
        self.assertEqual(load("rig.launch", "load_cell_rate:=1000", "lattice_rate:=20").params[
            "/rig/simulator/load_cell_rate"].value, 1000)
        config = load("rig.launch")
        self.assertNotIn("/rig/simulator/load_cell_rate", config.params)
        self.assertNotIn("/rig/simulator/lattice_rate", config.params)

    def test_the_rig_runs_on_this_machine_by_default(self):
        config = load("rig.launch")
        self.assertEqual(host(config, "simulator"), "")


if __name__ == "__main__":
    rosunit.unitrun("friction_sim", "launch_files", LaunchFilesTest)
