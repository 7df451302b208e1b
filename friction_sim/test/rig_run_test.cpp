// rostest node for whole runs through rig.launch. It watches a run, then asserts on what it saw and on
// the bag the simulator wrote.
//   mode "full": topics and types, stamps in simulated time, /clock monotonic, bad commands and bad
//     parameters refused while the rig keeps running, the bag holds every slip event with no gap in
//     the interface frames, the live and the replayed precursor detector agree with the simulator,
//     and the live run equals an offline run of the same scene and commands.
//   mode "kill": the simulator, fast-forwarding, killed mid-run leaves a readable bag with everything up
//     to the kill, load cells included at their rate across the jumps.
#include <friction_msgs/InterfaceState.h>
#include <friction_msgs/LatticeSnapshot.h>
#include <friction_msgs/PrecursorPoint.h>
#include <friction_msgs/SendStageCommand.h>
#include <friction_msgs/SetRunEnd.h>
#include <friction_msgs/SlipEvent.h>
#include <friction_msgs/StageState.h>
#include <friction_msgs/StrainGaugeProfile.h>
#include <geometry_msgs/WrenchStamped.h>
#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosgraph_msgs/Clock.h>
#include <std_msgs/String.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "friction_sim/instruments/results_io.h"
#include "friction_sim/ros/conversions.h"
#include "friction_sim/ros/node_parameters.h"
#include "friction_sim/ros/precursor_detector.h"
#include "friction_sim/ros/rig_simulator.h"
#include "friction_sim/run/run_driver.h"
#include "friction_sim/run/simulation.h"
#include "friction_sim/scene/loading_protocol.h"
#include "friction_sim/scene/scene_io.h"
#include "text_file.h"

namespace friction {
namespace {

using testing::readFile;

/// What a run showed on its topics.
struct Observed {
  std::vector<friction_msgs::SlipEvent> events;
  std::vector<friction_msgs::PrecursorPoint> live_points, replay_points;
  std::vector<friction_msgs::SlipEvent> live_detector_events, replay_detector_events;
  std::vector<double> clock, load_cell_stamps;
  bool subscriptions_connected = false;  ///< each of the test's subscriptions heard its publisher
  int gauge_profiles = 0;
  double last_stage_time = 0.0;
  int stage_states = 0;
  int lattice_snapshots = 0;
  friction_msgs::LatticeSnapshot last_lattice;
  std::map<std::string, std::string> topic_types;
  std::vector<friction_msgs::SendStageCommand::Response> bad_command_replies;
  double time_after_bad_commands = 0.0;
  std::string bad_scene_output, bad_parameter_output, bad_protocol_output, bad_detector_output;
  int bad_scene_status = 0, bad_parameter_status = 0, bad_protocol_status = 0, bad_detector_status = 0;
  int aborts_after_bad_protocol = 0, stops_after_bad_protocol = 0;
  std::string refused_command_output;
  int refused_command_status = 0, aborts_after_refused_command = 0, stops_after_refused_command = 0,
      unpauses_after_refused_command = 0;
  int reset_controller_status = -1, commands_around_reset = 0, run_ends_around_reset = 0, unpauses_around_reset = 0;
  std::string reset_controller_output;
  int failed_call_controller_status = -1, commands_with_a_failed_call = 0;
  std::string failed_call_controller_output;
};
Observed g_seen;
std::string g_bag;

/// Runs a command, returning its exit status and output.
int runCommand(const std::string& command, std::string& output) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  char buffer[512];
  while (fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// A shell command run in the background for the object's lifetime; interrupted (SIGINT) at its end, and
/// killed if it has not ended 5 s later (rosbag play still waiting for subscribers ignores SIGINT).
class BackgroundCommand {
 public:
  explicit BackgroundCommand(const std::string& command) {
    const std::string exec_command = "exec " + command + " >/dev/null 2>&1";
    pid_ = fork();
    if (pid_ == 0) {
      execl("/bin/sh", "sh", "-c", exec_command.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    EXPECT_GT(pid_, 0) << "cannot start " << command;
  }
  BackgroundCommand(const BackgroundCommand&) = delete;
  BackgroundCommand& operator=(const BackgroundCommand&) = delete;
  ~BackgroundCommand() {
    if (pid_ <= 0) return;
    kill(pid_, SIGINT);
    for (int waited = 0; waited < 50; ++waited) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) return;
      ros::WallDuration(0.1).sleep();
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }

 private:
  pid_t pid_;
};

/// A path in /tmp named after this test node (`what` appended): full_run and full_run_rate_state run at
/// the same time under `run_tests -j2`.
std::string ownTemporaryPath(const std::string& what) { return "/tmp/" + ros::this_node::getName().substr(1) + what; }

bool waitFor(const std::function<bool()>& condition, double seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    if (condition()) return true;
    ros::WallDuration(0.01).sleep();
  }
  return condition();
}

template <class Message, class Callback>
ros::Subscriber listen(ros::NodeHandle& nh, const std::string& topic, Callback callback) {
  return nh.subscribe<Message>(topic, 10000, boost::function<void(const typename Message::ConstPtr&)>(callback));
}

/// Subscribes to `topic`, keeping every message in `kept`.
template <class Message>
ros::Subscriber keep(ros::NodeHandle& nh, const std::string& topic, std::vector<Message>& kept) {
  return listen<Message>(nh, topic, [&kept](const typename Message::ConstPtr& m) { kept.push_back(*m); });
}

/// A stand-in for the simulator, in a namespace of its own, for a controller run against it: its
/// services and its stage_state answer on a queue of their own while the controller runs.
class StandInSimulator {
 public:
  explicit StandInSimulator(const std::string& ns) : ns_(ns), nh_(ns) {
    nh_.setCallbackQueue(&queue_);
    state_ = nh_.advertise<friction_msgs::StageState>("stage_state", 1, true);
  }
  /// Serves `name` with `callback`, whose false fails the call.
  template <class Service>
  void serve(const std::string& name,
             const boost::function<bool(typename Service::Request&, typename Service::Response&)>& callback) {
    services_.push_back(nh_.advertiseService(name, callback));
  }
  /// Answers the service `name` with `reply` (which fills the response) and true.
  template <class Service>
  void answer(const std::string& name,
              std::function<void(typename Service::Request&, typename Service::Response&)> reply) {
    serve<Service>(name, [reply](typename Service::Request& request, typename Service::Response& response) {
      reply(request, response);
      return true;
    });
  }
  /// Accepts every call to its service `name` (send_command, set_run_end), counting them in `calls`.
  template <class Service>
  void acceptCalls(const std::string& name, int& calls) {
    answer<Service>(name, [&calls](typename Service::Request&, typename Service::Response& response) {
      ++calls;
      response.accepted = true;
    });
  }
  /// Counts the calls to its Trigger service `name` (stop, abort) in `calls`.
  void countCalls(const std::string& name, int& calls) {
    answer<std_srvs::Trigger>(name, [&calls](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
      ++calls;
      response.success = true;
    });
  }
  /// Publishes its stage state (latched): F_Z = 1920 N at simulated `time`.
  void announce(std::uint32_t resets, double time, std::uint32_t global_events, bool paused) {
    friction_msgs::StageState msg;
    msg.header.stamp = ros::Time(time);
    msg.normal_force = 1920.0;
    msg.resets = resets;
    msg.global_events = global_events;
    msg.paused = paused;
    state_.publish(msg);
  }
  /// Runs the controller on `protocol` with `parameters` ("_name:=value ..."); its exit status.
  int runController(const std::string& protocol, const std::string& parameters, std::string& output) {
    ros::AsyncSpinner spinner(1, &queue_);
    spinner.start();
    const int status = runCommand("rosrun friction_sim stage_controller __name:=controller __ns:=" + ns_ + " " +
                                      parameters + " _protocol:=" + protocol,
                                  output);
    spinner.stop();
    return status;
  }

 private:
  std::string ns_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;
  ros::Publisher state_;
  std::vector<ros::ServiceServer> services_;
};

/// A controller given a bad protocol, against a simulator that is only a stop service.
void runRefusedProtocol() {
  const std::string protocol = ownTemporaryPath("_bad_protocol.yaml");
  std::FILE* file = std::fopen(protocol.c_str(), "w");
  std::fputs("steps:\n  - {action: drive, speed: .nan, duration: -1.0}\nend: {global_events: 1}\n", file);
  std::fclose(file);
  StandInSimulator simulator("/refused_protocol");
  simulator.countCalls("abort", g_seen.aborts_after_bad_protocol);
  simulator.countCalls("stop", g_seen.stops_after_bad_protocol);
  g_seen.bad_protocol_status = simulator.runController(protocol, "", g_seen.bad_protocol_output);
}

/// A controller whose simulator announces t = 0, refuses every command and counts the calls to abort,
/// stop and unpause.
void runProtocolAgainstARefusingSimulator(const std::string& protocol) {
  StandInSimulator simulator("/refused_command");
  simulator.answer<friction_msgs::SendStageCommand>(
      "send_command",
      [](friction_msgs::SendStageCommand::Request&, friction_msgs::SendStageCommand::Response& response) {
        response.accepted = false;
        response.reason = "speed 2 m/s exceeds the stage's max_speed 1 m/s";
      });
  simulator.countCalls("abort", g_seen.aborts_after_refused_command);
  simulator.countCalls("stop", g_seen.stops_after_refused_command);
  simulator.answer<std_srvs::SetBool>("pause",
                                      [](std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response) {
                                        if (!request.data) ++g_seen.unpauses_after_refused_command;
                                        response.success = true;
                                      });
  simulator.announce(0, 0.0, 0, true);
  g_seen.refused_command_status = simulator.runController(protocol, "_start_delay:=0", g_seen.refused_command_output);
}

/// A controller whose simulator is reset while it waits to start: the stand-in announces t = 0, takes
/// every command and run end, and when first unpaused announces a reset with the time still 0 (the
/// count of resets alone shows it), then, unpaused again, the protocol's end (two global events).
void runControllerThroughAResetAtTheStart(const std::string& protocol) {
  StandInSimulator simulator("/reset_at_start");
  simulator.acceptCalls<friction_msgs::SendStageCommand>("send_command", g_seen.commands_around_reset);
  simulator.acceptCalls<friction_msgs::SetRunEnd>("set_run_end", g_seen.run_ends_around_reset);
  simulator.answer<std_srvs::SetBool>(
      "pause", [&simulator](std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response) {
        if (!request.data && ++g_seen.unpauses_around_reset == 1) simulator.announce(1, 0.0, 0, true);
        if (!request.data && g_seen.unpauses_around_reset == 2) simulator.announce(1, 0.1, 2, false);
        response.success = true;
      });
  simulator.announce(0, 0.0, 0, true);
  g_seen.reset_controller_status = simulator.runController(protocol, "_start_delay:=0", g_seen.reset_controller_output);
}

/// A controller whose simulator fails the first send_command call (as a lost connection would) and
/// takes every other command, then announces the protocol's end when unpaused.
void runControllerThroughAFailedCall(const std::string& protocol) {
  int run_ends = 0;  // outlives the stand-in's services
  StandInSimulator simulator("/failed_call");
  simulator.serve<friction_msgs::SendStageCommand>(
      "send_command",
      [](friction_msgs::SendStageCommand::Request&, friction_msgs::SendStageCommand::Response& response) {
        response.accepted = true;
        return ++g_seen.commands_with_a_failed_call > 1;
      });
  simulator.acceptCalls<friction_msgs::SetRunEnd>("set_run_end", run_ends);
  simulator.answer<std_srvs::SetBool>(
      "pause", [&simulator](std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response) {
        if (!request.data) simulator.announce(0, 0.1, 2, false);
        response.success = true;
      });
  simulator.announce(0, 0.0, 0, true);
  g_seen.failed_call_controller_status =
      simulator.runController(protocol, "_start_delay:=0", g_seen.failed_call_controller_output);
}

/// The scene rig.launch ran: the test's ~scene with its ~overrides.
Scene launchedScene() {
  ros::NodeHandle pnh("~");
  std::string scene_path, overrides;
  pnh.getParam("scene", scene_path);
  pnh.getParam("overrides", overrides);
  std::vector<std::string> problems;
  const auto parsed = parseOverrides(overrides, problems);
  EXPECT_TRUE(problems.empty());
  return loadScene(scene_path, parsed);
}

/// The commands of the test's ~protocol, as its controller schedules them from t = 0.
std::vector<TimedCommand> launchedSchedule(const Scene& scene) {
  std::string protocol_path;
  ros::NodeHandle("~").getParam("protocol", protocol_path);
  std::vector<TimedCommand> schedule = scheduleProtocol(loadProtocol(protocol_path), 0.0, scene.load.normal_force);
  // As the rig receives them: each at the time its stamp carries, which a sum of durations need not be.
  for (TimedCommand& command : schedule) command.time = stampSeconds(command.time);
  return schedule;
}

bool bagReadable(const std::string& path) {
  try {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    return true;
  } catch (const rosbag::BagException&) {
    return false;
  }
}

template <class Message>
std::vector<typename Message::ConstPtr> readTopic(const std::string& path, const std::string& topic) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<typename Message::ConstPtr> out;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    if (auto msg = m.instantiate<Message>()) out.push_back(msg);
  }
  return out;
}

void checkBagHasEveryEventAndNoFrameGap(const std::vector<friction_msgs::SlipEvent>& live) {
  ASSERT_TRUE(bagReadable(g_bag)) << g_bag;
  const auto events = readTopic<friction_msgs::SlipEvent>(g_bag, "/rig/slip_events");
  ASSERT_GE(events.size(), live.size());
  for (std::size_t e = 0; e < live.size(); ++e) {
    EXPECT_EQ(events[e]->index, live[e].index);
    EXPECT_EQ(events[e]->onset_time, live[e].onset_time);
    EXPECT_EQ(events[e]->rupture_length, live[e].rupture_length);
    EXPECT_EQ(events[e]->node_slip, live[e].node_slip);
  }
  const auto frames = readTopic<friction_msgs::InterfaceState>(g_bag, "/rig/interface");
  ASSERT_FALSE(frames.empty());
  for (std::size_t f = 0; f < frames.size(); ++f) ASSERT_EQ(frames[f]->frame_index, f) << "gap before frame " << f;
}

/// The bag's load cells at 10 kHz of simulated time, in time order, plus one sample at each event's
/// start and end: also across fast-forward jumps, where they are interpolated.
void expectLoadCellsEvery100Microseconds() {
  const auto cells = readTopic<geometry_msgs::WrenchStamped>(g_bag, "/rig/load_cells");
  ASSERT_GT(cells.size(), 100u);
  const double span = cells.back()->header.stamp.toSec() - cells.front()->header.stamp.toSec();
  // Counted in the bag: a killed run's simulator may have gone on past the events the test saw.
  const double extra = 2.0 * readTopic<friction_msgs::SlipEvent>(g_bag, "/rig/slip_events").size();
  EXPECT_NEAR(cells.size() - extra, span * 1e4, 0.01 * span * 1e4 + 2);
  double longest_gap = 0.0;
  for (std::size_t i = 1; i < cells.size(); ++i) {
    ASSERT_GE(cells[i]->header.stamp, cells[i - 1]->header.stamp);
    longest_gap = std::max(longest_gap, (cells[i]->header.stamp - cells[i - 1]->header.stamp).toSec());
  }
  // While the dynamics steps, a sample comes at the first step (0.4 µs) at or after its time.
  EXPECT_LE(longest_gap, 1e-4 + 4e-7 + 1e-12);
}

TEST(FullRun, TopicsHaveTheirTypesAndSimulatedTimeStamps) {
  EXPECT_TRUE(g_seen.subscriptions_connected);
  EXPECT_EQ(g_seen.topic_types["/rig/load_cells"], "geometry_msgs/WrenchStamped");
  EXPECT_EQ(g_seen.topic_types["/rig/interface"], "friction_msgs/InterfaceState");
  EXPECT_EQ(g_seen.topic_types["/rig/strain_gauges"], "friction_msgs/StrainGaugeProfile");
  EXPECT_EQ(g_seen.topic_types["/rig/slip_events"], "friction_msgs/SlipEvent");
  EXPECT_EQ(g_seen.topic_types["/rig/stage_state"], "friction_msgs/StageState");
  EXPECT_EQ(g_seen.topic_types["/rig/lattice"], "friction_msgs/LatticeSnapshot");
  EXPECT_EQ(g_seen.topic_types["/clock"], "rosgraph_msgs/Clock");
  ASSERT_GT(g_seen.clock.size(), 10u);
  for (std::size_t i = 1; i < g_seen.clock.size(); ++i) ASSERT_GE(g_seen.clock[i], g_seen.clock[i - 1]);
  expectLoadCellsEvery100Microseconds();
  EXPECT_GT(g_seen.gauge_profiles, 0);
  EXPECT_GT(g_seen.stage_states, 0);
}

TEST(FullRun, EveryNodeParameterIsOnTheParameterServerDefaultsIncluded) {
  // None of these is set by the launch files: each node wrote back the default it ran with.
  double clock_rate = 0.0;
  std::string compression, frame;
  int fit_nodes = 0;
  ASSERT_TRUE(ros::param::get("/rig/simulator/clock_rate", clock_rate));
  EXPECT_EQ(clock_rate, SimulatorOptions().clock_rate);
  ASSERT_TRUE(ros::param::get("/rig/simulator/bag_compression", compression));
  EXPECT_EQ(compression, "lz4");
  ASSERT_TRUE(ros::param::get("/rig/simulator/frame_id", frame));
  EXPECT_EQ(frame, "slider");
  ASSERT_TRUE(ros::param::get("/rig/precursor_detector/front_fit_nodes", fit_nodes));
  EXPECT_EQ(fit_nodes, DetectorOptions().front_fit_nodes);
}

TEST(FullRun, StageTravelFollowsThePositionAcrossFastForwardJumps) {
  // The protocol holds, then drives forward only: travel is the distance from the start, also in the
  // stage states interpolated across a jump (not the travel at the jump's end).
  const auto states = readTopic<friction_msgs::StageState>(g_bag, "/rig/stage_state");
  ASSERT_GT(states.size(), 50u);  // 1 kHz over 55 ms
  for (const auto& state : states) {
    ASSERT_NEAR(state->travel, state->position, 1e-12) << "at t = " << state->header.stamp.toSec();
  }
  EXPECT_GT(states.back()->travel, 0.0);
}

TEST(FullRun, GaugesAreFastDuringEventsAndSlowBetweenThem) {
  // The full-run tests give gauge_idle_rate as roslaunch's string "2e3": read as the number and written
  // back as one. In the bag, each profile taken during an event is followed within 10 µs (100 kHz, the
  // default) and a step of 0.4 µs; between events, profiles come every 0.5 ms, give or take a step. An
  // event may run on after its end for the quiet time that confirms it: one shear-wave transit L/c_S
  // under the slip-speed rule (coarse_2d_rate_state's), none under the other (coarse_2d's). The idle
  // spacing is checked outside that window, widened by two steps for the stamps' rounding.
  double idle_rate = 0.0;
  ASSERT_TRUE(ros::param::get("/rig/simulator/gauge_idle_rate", idle_rate));
  EXPECT_EQ(idle_rate, 2e3);
  const auto profiles = readTopic<friction_msgs::StrainGaugeProfile>(g_bag, "/rig/strain_gauges");
  const auto events = readTopic<friction_msgs::SlipEvent>(g_bag, "/rig/slip_events");
  ASSERT_GE(events.size(), 2u);
  const double dt = 4e-7, slack = 1e-9;  // stamps are whole nanoseconds
  auto during_event = [&events](double t) {
    return std::any_of(events.begin(), events.end(),
                       [t](const auto& e) { return e->onset_time <= t && t < e->end_time; });
  };
  auto near_event = [&events, dt](double t) {
    return std::any_of(events.begin(), events.end(), [t, dt](const auto& e) {
      return e->onset_time <= t && t <= e->end_time + e->slider_length / e->shear_wave_speed + 2.0 * dt;
    });
  };
  auto onset_between = [&events](double a, double b) {
    return std::any_of(events.begin(), events.end(),
                       [a, b](const auto& e) { return a <= e->onset_time && e->onset_time <= b; });
  };
  int fast = 0, slow = 0;
  for (std::size_t k = 0; k + 1 < profiles.size(); ++k) {
    const double t = profiles[k]->header.stamp.toSec(), next = profiles[k + 1]->header.stamp.toSec();
    if (during_event(t)) {
      ++fast;
      EXPECT_LE(next - t, 1e-5 + dt + slack) << "after t = " << t;
    } else if (!near_event(t) && !near_event(next) && !onset_between(t, next)) {
      ++slow;
      EXPECT_NEAR(next - t, 1.0 / idle_rate, dt + slack) << "after t = " << t;
    }
  }
  EXPECT_GT(fast, static_cast<int>(events.size()));
  EXPECT_GT(slow, 10);
}

TEST(FullRun, LatticeSnapshotsShowTheLoadedSlider) {
  ASSERT_GT(g_seen.lattice_snapshots, 0);
  const auto& lattice = g_seen.last_lattice;
  ros::NodeHandle pnh("~");
  std::string scene_path;
  pnh.getParam("scene", scene_path);
  const Scene scene = loadScene(scene_path);
  ASSERT_EQ(lattice.nodes_x, static_cast<unsigned>(scene.lattice.nodes_x));
  ASSERT_EQ(lattice.nodes_z, static_cast<unsigned>(scene.lattice.nodes_z));
  const std::size_t nodes = lattice.nodes_x * lattice.nodes_z;
  for (const auto* field :
       {&lattice.x, &lattice.z, &lattice.speed, &lattice.sigma_xx, &lattice.sigma_zz, &lattice.tau_xz}) {
    ASSERT_EQ(field->size(), nodes);
  }
  ASSERT_EQ(lattice.interface_state.size(), lattice.nodes_x);
  EXPECT_DOUBLE_EQ(lattice.spacing, scene.geometry.length / (scene.lattice.nodes_x - 1));
  EXPECT_DOUBLE_EQ(lattice.normal_force, scene.load.normal_force);
  // Nodes sit at their rest places give or take the micrometres of elastic displacement and slip: along
  // x, at most twice the shortening of the whole slider under the largest F_X its interface holds,
  // µ_s·F_Z·L/(E·H·B) (twice: the pusher's load concentrates near the bottom).
  const double shortening = 2.0 * scene.friction.initialStaticCoefficient() * scene.load.normal_force *
                            scene.geometry.length /
                            (scene.material.youngs_modulus * scene.geometry.height * scene.geometry.width);
  double top_sigma_zz = 0.0;
  for (std::size_t j = 0; j < lattice.nodes_z; ++j) {
    for (std::size_t i = 0; i < lattice.nodes_x; ++i) {
      const std::size_t node = j * lattice.nodes_x + i;
      EXPECT_NEAR(lattice.z[node], j * lattice.spacing, 1e-4);
      EXPECT_NEAR(lattice.x[node] - lattice.x[j * lattice.nodes_x], i * lattice.spacing, shortening);
      if (j + 1 == lattice.nodes_z) top_sigma_zz += lattice.sigma_zz[node] / lattice.nodes_x;
    }
  }
  // Under the uniform top load the top row carries σ_zz = −F_Z/(L·B); the corners' half-cells and
  // the pusher's moment leave a few per cent.
  const double applied = -scene.load.normal_force / (scene.geometry.length * scene.geometry.width);
  EXPECT_NEAR(top_sigma_zz, applied, 0.05 * std::abs(applied)) << "top row mean σ_zz " << top_sigma_zz;
}

TEST(FullRun, BadCommandsAndParametersAreRefusedAndTheRigKeepsRunning) {
  ASSERT_EQ(g_seen.bad_command_replies.size(), 3u);
  for (const auto& reply : g_seen.bad_command_replies) {
    EXPECT_FALSE(reply.accepted);
    EXPECT_FALSE(reply.reason.empty());
  }
  EXPECT_NE(g_seen.bad_command_replies[0].reason.find("finite"), std::string::npos);
  EXPECT_NE(g_seen.bad_command_replies[1].reason.find("normal load -5 N"), std::string::npos);
  EXPECT_NE(g_seen.bad_command_replies[2].reason.find("max_speed"), std::string::npos);
  EXPECT_GT(g_seen.last_stage_time, g_seen.time_after_bad_commands);
  EXPECT_EQ(g_seen.bad_scene_status, 2);
  EXPECT_NE(g_seen.bad_scene_output.find("scene refused"), std::string::npos) << g_seen.bad_scene_output;
  EXPECT_NE(g_seen.bad_scene_output.find("friction.kinetic_coefficient: value 0.9"), std::string::npos);
  EXPECT_NE(g_seen.bad_scene_output.find("pusher.height: value 1"), std::string::npos);
  // The precursor detector refuses its parameters at start, every problem named.
  EXPECT_EQ(g_seen.bad_detector_status, 2);
  EXPECT_NE(g_seen.bad_detector_output.find("~front_fit_nodes: value 1 is not allowed"), std::string::npos)
      << g_seen.bad_detector_output;
  EXPECT_NE(g_seen.bad_detector_output.find("~overrides: 'broken' given without ~scene"), std::string::npos)
      << g_seen.bad_detector_output;
  EXPECT_EQ(g_seen.bad_parameter_status, 2);
  EXPECT_NE(g_seen.bad_parameter_output.find("~load_cell_rate: value -1"), std::string::npos)
      << g_seen.bad_parameter_output;
  EXPECT_NE(g_seen.bad_parameter_output.find("~gauge_rate: value 'fast' is not allowed; allowed: a number"),
            std::string::npos)
      << g_seen.bad_parameter_output;
  // A refused protocol lists every problem, and the controller aborts the run of the simulator that waits
  // for it rather than leave it waiting (the simulator then exits with status 4: test_rig_launch.py).
  EXPECT_EQ(g_seen.bad_protocol_status, 2);
  EXPECT_NE(g_seen.bad_protocol_output.find("protocol refused (2 problems)"), std::string::npos)
      << g_seen.bad_protocol_output;
  EXPECT_EQ(g_seen.aborts_after_bad_protocol, 1);
  EXPECT_EQ(g_seen.stops_after_bad_protocol, 0);
  // A protocol the simulator refuses a command of is not run under what the simulator had before: the
  // controller aborts its run without unpausing it, and exits with status 2.
  EXPECT_EQ(g_seen.refused_command_status, 2) << g_seen.refused_command_output;
  EXPECT_NE(g_seen.refused_command_output.find("refused: speed 2 m/s exceeds the stage's max_speed"), std::string::npos)
      << g_seen.refused_command_output;
  EXPECT_EQ(g_seen.aborts_after_refused_command, 1);
  EXPECT_EQ(g_seen.stops_after_refused_command, 0);
  EXPECT_EQ(g_seen.unpauses_after_refused_command, 0);
}

TEST(FullRun, ControllerSendsACommandAgainWhenItsCallFailsAndRunsTheProtocol) {
  // The failed call is sent once more on a new connection: every command arrives, the run is not
  // aborted, and the controller exits cleanly at the protocol's end.
  ros::NodeHandle pnh("~");
  std::string protocol;
  pnh.getParam("protocol", protocol);
  const std::size_t schedule = scheduleProtocol(loadProtocol(protocol), 0.0, 1920.0).size();
  EXPECT_EQ(g_seen.commands_with_a_failed_call, static_cast<int>(schedule + 1));
  EXPECT_EQ(g_seen.failed_call_controller_status, 0) << g_seen.failed_call_controller_output;
  EXPECT_NE(g_seen.failed_call_controller_output.find("send_command failed; reconnecting"), std::string::npos)
      << g_seen.failed_call_controller_output;
}

TEST(FullRun, ControllerStartsOverAfterAResetThatCameBeforeTimeMovedOn) {
  // The schedule and the run end are sent again after the reset; the simulator ends the run at the
  // protocol's end, and the controller exits cleanly.
  ros::NodeHandle pnh("~");
  std::string protocol;
  pnh.getParam("protocol", protocol);
  const std::size_t schedule = scheduleProtocol(loadProtocol(protocol), 0.0, 1920.0).size();
  EXPECT_EQ(g_seen.reset_controller_status, 0) << g_seen.reset_controller_output;
  EXPECT_EQ(g_seen.commands_around_reset, static_cast<int>(2 * schedule));
  EXPECT_EQ(g_seen.run_ends_around_reset, 2);
  EXPECT_EQ(g_seen.unpauses_around_reset, 2);
}

TEST(FullRun, BagHoldsEverySlipEventAndEveryInterfaceFrame) {
  ASSERT_GE(g_seen.events.size(), 2u);
  checkBagHasEveryEventAndNoFrameGap(g_seen.events);
}

TEST(FullRun, BagHoldsTheSceneAsRunFirstAndAgainWithTheProtocolsEnd) {
  ASSERT_TRUE(bagReadable(g_bag)) << g_bag;
  const auto scenes = readTopic<std_msgs::String>(g_bag, "/rig/scene");
  ASSERT_EQ(scenes.size(), 2u);
  // The recorded text reads back as the scene the launch named, its overrides applied, field for field;
  // then with the end the controller set (two_global_events.yaml) as its stop condition.
  Scene as_run = launchedScene();
  EXPECT_EQ(sceneToYaml(parseScene(scenes[0]->data)), sceneToYaml(as_run));
  as_run.stop = StopSpec{2, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  EXPECT_EQ(sceneToYaml(parseScene(scenes[1]->data)), sceneToYaml(as_run));
  rosbag::Bag bag(g_bag);
  rosbag::View everything(bag);
  ASSERT_GT(everything.size(), 0u);
  EXPECT_EQ(everything.begin()->getTopic(), "/rig/scene");
  // Latched, so that a bag played before its listeners connect still gives it to them.
  EXPECT_EQ(everything.begin()->getConnectionHeader()->at("latching"), "1");
}

void expectPointsMatchEvents(const std::vector<friction_msgs::PrecursorPoint>& points) {
  ASSERT_FALSE(g_seen.events.empty());
  ASSERT_EQ(points.size(), g_seen.events.size());
  for (std::size_t e = 0; e < points.size(); ++e) {
    const auto& event = g_seen.events[e];
    EXPECT_EQ(points[e].global_event, event.global_event);
    EXPECT_DOUBLE_EQ(points[e].length_ratio, event.rupture_length / event.slider_length);
    // The detector reads F_X at the end of the onset step, the simulator within it: they differ by
    // at most one step of loading, K·V·dt/F_Z = 3.3e-6 in this scene.
    EXPECT_NEAR(points[e].shear_ratio, event.onset_shear_force / event.onset_normal_force, 1e-5);
  }
}

TEST(FullRun, LivePrecursorDetectorAgreesWithTheSimulator) { expectPointsMatchEvents(g_seen.live_points); }

TEST(FullRun, ReplayedBagGivesTheSamePrecursorPoints) { expectPointsMatchEvents(g_seen.replay_points); }

TEST(FullRun, DetectorTakesTheWaveSpeedsFromTheRunsSceneGivenOrRecorded) {
  // rig.launch gives the live detector the run's scene file; the replaying one has none (full_run.test)
  // and takes the scene the bag recorded.
  for (const auto* detector_events : {&g_seen.live_detector_events, &g_seen.replay_detector_events}) {
    ASSERT_EQ(detector_events->size(), g_seen.events.size());
    for (std::size_t e = 0; e < g_seen.events.size(); ++e) {
      const auto& detected = (*detector_events)[e];
      const auto& simulated = g_seen.events[e];
      EXPECT_NEAR(detected.shear_wave_speed, 968.2, 0.1);  // MODEL.md §2, the default material
      EXPECT_EQ(detected.shear_wave_speed, simulated.shear_wave_speed);
      EXPECT_EQ(detected.rayleigh_speed, simulated.rayleigh_speed);
      EXPECT_EQ(detected.longitudinal_wave_speed, simulated.longitudinal_wave_speed);
      EXPECT_EQ(detected.slider_length, simulated.slider_length);
    }
  }
}

TEST(FullRun, BagHoldsTheCommandsAsApplied) {
  // The protocol's schedule, each command at the first step at or after its time; the refused commands
  // sent while the rig ran are not among them.
  const Scene scene = launchedScene();
  const auto schedule = launchedSchedule(scene);
  const auto applied = readTopic<friction_msgs::StageCommand>(g_bag, "/rig/applied_commands");
  ASSERT_EQ(applied.size(), schedule.size());
  for (std::size_t c = 0; c < schedule.size(); ++c) {
    const TimedCommand recorded = fromMsg(*applied[c]);
    EXPECT_GE(recorded.time, schedule[c].time - 1e-9);
    EXPECT_LT(recorded.time, schedule[c].time + scene.integrator.time_step);
    EXPECT_EQ(recorded.stage.mode, schedule[c].stage.mode);
    EXPECT_EQ(recorded.stage.speed, schedule[c].stage.speed);
  }
}

TEST(FullRun, LiveRunEqualsTheOfflineRunOfTheSameSceneAndCommands) {
  // As the simulator node runs: the commands due by now applied before the step, and a fast-forward
  // jump cut only where the next command is due (the instruments are interpolated across it).
  const Scene scene = launchedScene();
  RunDriver driver(scene, requireValidScene(scene));
  const Simulation& offline = driver.simulation();
  ASSERT_TRUE(offline.scene().integrator.fast_forward);
  for (const TimedCommand& command : launchedSchedule(offline.scene())) driver.schedule(command);
  driver.onCommandDue([](const TimedCommand&, const std::string& refusal) { EXPECT_EQ(refusal, ""); });
  while (offline.globalEventCount() < 2 && offline.time() < 5.0) driver.advance();
  EXPECT_GT(offline.jumps(), 0);
  // The simulator ends the run itself on the step of the protocol's end (set_run_end), however late the
  // controller hears of it: the live run holds the same events and ends at the same step.
  ASSERT_EQ(g_seen.events.size(), offline.events().size());
  EXPECT_NEAR(g_seen.last_stage_time, offline.time(), 1e-9);  // a stamp keeps nanoseconds
  for (std::size_t e = 0; e < offline.events().size(); ++e) {
    EXPECT_EQ(offline.events()[e].onset_time, g_seen.events[e].onset_time);
    EXPECT_EQ(offline.events()[e].onset_shear_force, g_seen.events[e].onset_shear_force);
    EXPECT_EQ(offline.events()[e].mean_shear_force, g_seen.events[e].mean_shear_force);
    EXPECT_EQ(offline.events()[e].node_slip, g_seen.events[e].node_slip);
  }
  // rig_report's table from the bag is the offline runner's events.csv, to the last digit.
  std::ostringstream offline_table;
  writeEventsCsv(offline_table, offline.events(), offline.scene());
  const std::string out = ownTemporaryPath("_report");
  std::string output;
  ASSERT_EQ(runCommand("rosrun friction_sim rig_report " + g_bag + " --out " + out, output), 0) << output;
  EXPECT_EQ(readFile(out + "/events.csv"), offline_table.str());
  // And the offline runner, given the scene and the commands rig_report wrote from the bag (the command
  // it prints), reruns the live run to the last digit.
  const std::string arguments = out + "/scene.yaml --commands " + out + "/stage_commands.csv --out " + out + "/rerun";
  EXPECT_NE(output.find("/friction_run " + arguments), std::string::npos) << output;
  ASSERT_EQ(runCommand("rosrun friction_sim friction_run " + arguments, output), 0) << output;
  EXPECT_EQ(readFile(out + "/rerun/events.csv"), offline_table.str());
  // So does the offline runner given the launch's scene, overrides and protocol.
  std::string scene_path, overrides, protocol_path;
  ros::NodeHandle("~").getParam("scene", scene_path);
  ros::NodeHandle("~").getParam("overrides", overrides);
  ros::NodeHandle("~").getParam("protocol", protocol_path);
  ASSERT_EQ(runCommand("rosrun friction_sim friction_run " + scene_path + " --set " + overrides + " --protocol " +
                           protocol_path + " --out " + out + "/protocol_run",
                       output),
            0)
      << output;
  EXPECT_EQ(readFile(out + "/protocol_run/events.csv"), offline_table.str());
}

TEST(KillRun, BagIsReadableAndHoldsEverythingUpToTheKill) {
  ASSERT_GE(g_seen.events.size(), 2u);
  checkBagHasEveryEventAndNoFrameGap(g_seen.events);
  // This run fast-forwards between events (kill_run.test): the load cells go on across the jumps.
  expectLoadCellsEvery100Microseconds();
}

void watchFullRun(ros::NodeHandle& nh) {
  auto rig = std::make_shared<ros::NodeHandle>("/rig");
  std::vector<ros::Subscriber> subs;
  subs.push_back(keep(nh, "/rig/precursor_detector/precursor_points", g_seen.live_points));
  subs.push_back(keep(nh, "/replay/precursor_detector/precursor_points", g_seen.replay_points));
  subs.push_back(keep(nh, "/rig/precursor_detector/slip_events", g_seen.live_detector_events));
  subs.push_back(keep(nh, "/replay/precursor_detector/slip_events", g_seen.replay_detector_events));
  subs.push_back(listen<rosgraph_msgs::Clock>(
      nh, "/clock", [](const rosgraph_msgs::Clock::ConstPtr& m) { g_seen.clock.push_back(m->clock.toSec()); }));
  subs.push_back(listen<friction_msgs::StrainGaugeProfile>(
      nh, "/rig/strain_gauges", [](const friction_msgs::StrainGaugeProfile::ConstPtr&) { ++g_seen.gauge_profiles; }));
  subs.push_back(
      listen<friction_msgs::StageState>(nh, "/rig/stage_state", [](const friction_msgs::StageState::ConstPtr& m) {
        ++g_seen.stage_states;
        g_seen.last_stage_time = m->header.stamp.toSec();
      }));
  subs.push_back(
      listen<friction_msgs::LatticeSnapshot>(nh, "/rig/lattice", [](const friction_msgs::LatticeSnapshot::ConstPtr& m) {
        ++g_seen.lattice_snapshots;
        g_seen.last_lattice = *m;
      }));
  // Bad commands to the rig while it waits at t = 0 for this test's subscription to its slip events
  // (full_run.test): with fast-forward the run itself is over in a tenth of a second, and calls made while
  // it ran could come after it had ended. Then a bad scene and a bad parameter for a second simulator.
  ros::service::waitForService("/rig/send_command", ros::Duration(60.0));
  ros::ServiceClient client = nh.serviceClient<friction_msgs::SendStageCommand>("/rig/send_command");
  for (auto [mode, speed, load] :
       {std::tuple<int, double, double>{0, std::nan(""), 0.0}, std::tuple<int, double, double>{3, 0.0, -5.0},
        std::tuple<int, double, double>{0, 50.0, 0.0}}) {
    friction_msgs::SendStageCommand call;
    call.request.command.mode = mode;
    call.request.command.speed = speed;
    call.request.command.normal_force = load;
    client.call(call);
    g_seen.bad_command_replies.push_back(call.response);
  }
  ros::master::V_TopicInfo topics;
  ros::master::getTopics(topics);
  for (const auto& topic : topics) g_seen.topic_types[topic.name] = topic.datatype;
  ros::spinOnce();
  g_seen.time_after_bad_commands = g_seen.last_stage_time;
  // Every other topic connected before the subscription that starts the run.
  g_seen.subscriptions_connected = waitFor(
      [&subs] {
        return std::all_of(subs.begin(), subs.end(),
                           [](const ros::Subscriber& sub) { return sub.getNumPublishers() > 0; });
      },
      240.0);
  subs.push_back(keep(nh, "/rig/slip_events", g_seen.events));
  const std::string bad_scene = ownTemporaryPath("_bad_scene.yaml");
  std::FILE* file = std::fopen(bad_scene.c_str(), "w");
  std::fputs("friction: {kinetic_coefficient: 0.9}\npusher: {height: 1.0}\n", file);
  std::fclose(file);
  g_seen.bad_scene_status =
      runCommand("rosrun friction_sim rig_simulator __name:=bad_scene _scene:=" + bad_scene, g_seen.bad_scene_output);
  ros::NodeHandle pnh("~");
  std::string scene;
  pnh.getParam("scene", scene);
  const std::string bad_parameters = " _load_cell_rate:=-1.0 _gauge_rate:=fast _scene:=" + scene;
  g_seen.bad_parameter_status = runCommand("rosrun friction_sim rig_simulator __name:=bad_parameter" + bad_parameters,
                                           g_seen.bad_parameter_output);
  g_seen.bad_detector_status =
      runCommand("rosrun friction_sim precursor_detector __name:=bad_detector _front_fit_nodes:=1 _overrides:=broken",
                 g_seen.bad_detector_output);
  runRefusedProtocol();
  {
    std::string protocol;
    pnh.getParam("protocol", protocol);
    runProtocolAgainstARefusingSimulator(protocol);
    runControllerThroughAResetAtTheStart(protocol);
    runControllerThroughAFailedCall(protocol);
  }
  // The controller ends the run after two global events; the simulator then closes its bag.
  waitFor([] { return bagReadable(g_bag); }, 240.0);
  waitFor([] { return g_seen.live_points.size() >= g_seen.events.size(); }, 10.0);
  // Replay the bag into the second detector, under its own names, once it listens: on a loaded machine
  // a fixed delay let the first frames go by before it had connected, and with them an event. The
  // player stays alive until the detector has caught up: a player that exits drops what its queues
  // still hold, and at ten times the pace that is most of the bag.
  const BackgroundCommand player("rosbag play --quiet --keep-alive --wait-for-subscribers -r 10 --queue 1000000 " +
                                 g_bag +
                                 " --topics /rig/scene /rig/load_cells /rig/interface /rig/scene:=/replay/scene"
                                 " /rig/load_cells:=/replay/load_cells /rig/interface:=/replay/interface");
  waitFor([] { return g_seen.replay_points.size() >= g_seen.events.size(); }, 120.0);
}

void watchKilledRun(ros::NodeHandle& nh) {
  ros::Subscriber events = keep(nh, "/rig/slip_events", g_seen.events);
  waitFor([] { return g_seen.events.size() >= 3; }, 240.0);
  std::string output;
  runCommand("rosnode kill /rig/simulator", output);
  waitFor([] { return bagReadable(g_bag); }, 60.0);
}

}  // namespace
}  // namespace friction

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rig_run_test");
  ros::NodeHandle nh, pnh("~");
  std::string mode;
  pnh.getParam("mode", mode);
  pnh.getParam("bag", friction::g_bag);
  if (mode == "kill") {
    friction::watchKilledRun(nh);
    testing::GTEST_FLAG(filter) = "KillRun.*";
  } else {
    friction::watchFullRun(nh);
    testing::GTEST_FLAG(filter) = "FullRun.*";
  }
  return RUN_ALL_TESTS();
}
