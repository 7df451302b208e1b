#include "friction_sim/ros/rig_simulator.h"

#include <boost/make_shared.hpp>
#include <rosgraph_msgs/Clock.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>

#include "friction_sim/ros/node_parameters.h"
#include "friction_sim/results_io.h"
#include "friction_sim/scene_io.h"

namespace friction {

std::atomic<bool> g_stop_requested{false};

namespace {

/// Advances a publication time past `now` on its regular grid; returns true if it was due.
bool due(double now, double& next, double rate) {
  if (now < next) return false;
  const double period = 1.0 / rate;
  next += period * (std::floor((now - next) / period) + 1.0);
  return true;
}

}  // namespace

std::vector<std::string> validateOptions(const SimulatorOptions& o) {
  std::vector<std::string> problems;
  auto require = [&](bool ok, const std::string& name, double value, const std::string& allowed) {
    requireSetting(ok, "~" + name, value, allowed, problems);
  };
  if (o.scene_path.empty()) problems.push_back("~scene: no value; allowed: the path of a scene YAML file");
  require(std::isfinite(o.real_time_factor) && o.real_time_factor >= 0.0, "real_time_factor", o.real_time_factor,
          ">= 0 (0 = as fast as possible)");
  const std::pair<const char*, double> rates[] = {
      {"load_cell_rate", o.load_cell_rate},   {"gauge_rate", o.gauge_rate},
      {"interface_rate", o.interface_rate},   {"interface_idle_rate", o.interface_idle_rate},
      {"stage_state_rate", o.stage_state_rate}, {"clock_rate", o.clock_rate},
      {"lattice_rate", o.lattice_rate}, {"snapshot_rate", o.snapshot_rate}};
  for (const auto& [name, rate] : rates) require(std::isfinite(rate) && rate > 0.0, name, rate, "a rate > 0 Hz");
  if (o.frame_id.empty()) problems.push_back("~frame_id: empty; allowed: a frame name such as 'slider'");
  parseOverrides(o.overrides, problems);
  return problems;
}

SimulatorOptions readSimulatorOptions(const ros::NodeHandle& pnh) {
  SimulatorOptions o;
  pnh.param("scene", o.scene_path, o.scene_path);
  pnh.param("overrides", o.overrides, o.overrides);
  pnh.param("real_time_factor", o.real_time_factor, o.real_time_factor);
  pnh.param("load_cell_rate", o.load_cell_rate, o.load_cell_rate);
  pnh.param("gauge_rate", o.gauge_rate, o.gauge_rate);
  pnh.param("interface_rate", o.interface_rate, o.interface_rate);
  pnh.param("interface_idle_rate", o.interface_idle_rate, o.interface_idle_rate);
  pnh.param("stage_state_rate", o.stage_state_rate, o.stage_state_rate);
  pnh.param("clock_rate", o.clock_rate, o.clock_rate);
  pnh.param("lattice_rate", o.lattice_rate, o.lattice_rate);
  pnh.param("snapshot_rate", o.snapshot_rate, o.snapshot_rate);
  pnh.param("bag", o.bag_path, o.bag_path);
  pnh.param("frame_id", o.frame_id, o.frame_id);
  pnh.param("stop_at_scene_end", o.stop_at_scene_end, o.stop_at_scene_end);
  pnh.param("start_paused", o.start_paused, o.start_paused);
  refuseParameters(pnh, validateOptions(o));
  return o;
}

std::string checkCommand(const friction_msgs::StageCommand& msg, const Simulation& simulation) {
  if (msg.mode > friction_msgs::StageCommand::NORMAL_LOAD) {
    return "mode " + std::to_string(msg.mode) + " is unknown; allowed: 0 VELOCITY, 1 HOLD, 2 POSITION, 3 NORMAL_LOAD";
  }
  return simulation.checkCommand(fromMsg(msg));
}

RigSimulator::RigSimulator(ros::NodeHandle nh, SimulatorOptions options)
    : nh_(std::move(nh)), options_(std::move(options)) {
  std::vector<std::string> problems;
  const auto overrides = parseOverrides(options_.overrides, problems);
  scene_ = loadScene(options_.scene_path, overrides, &stability_limit_);
  for (const std::string& warning : sceneWarnings(scene_)) ROS_WARN_STREAM("scene: " << warning);
  wave_speeds_ = waveSpeeds(scene_);
  // Opened before the run starts: a bag that cannot be written is refused rather than found out after
  // the loading solve, or lost at the end.
  if (!options_.bag_path.empty()) {
    try {
      bag_.open(options_.bag_path, rosbag::bagmode::Write);
    } catch (const rosbag::BagException& error) {
      throw ConfigError("parameters of " + ros::this_node::getName(),
                        {"~bag: value '" + options_.bag_path + "' cannot be written (" + error.what() +
                         "); allowed: a file path in a writable directory"});
    }
    bag_open_ = true;
  }
  startSimulation();
  advertise();
}

RigSimulator::~RigSimulator() {
  if (bag_open_) bag_.close();
}

void RigSimulator::startSimulation() {
  simulation_ = std::make_unique<Simulation>(scene_, stability_limit_);
  interface_positions_.clear();
  for (int node = 0; node < simulation_->model().interfaceNodeCount(); ++node) {
    interface_positions_.push_back(simulation_->model().interfacePosition(node));
  }
  pending_.clear();
  // Nothing is measured at t = 0 (a bag cannot hold a zero stamp): each stream starts one period in,
  // also when a fast-forward jump leaves t = 0 (a camera frame at 0, published and not recorded, would
  // leave a gap in the bag's frame_index).
  next_load_cells_ = 1.0 / options_.load_cell_rate;
  next_gauges_ = 1.0 / options_.gauge_rate;
  next_frame_ = 1.0 / options_.interface_idle_rate;
  next_stage_state_ = 1.0 / options_.stage_state_rate;
  next_clock_ = 1.0 / options_.clock_rate;
  next_lattice_ = 1.0 / options_.lattice_rate;
  next_snapshot_ = ros::WallTime::now();
  reset_requested_ = false;
  run_end_set_ = false;
  running_wall_time_ = 0.0;
  paused_ = true;  // a new simulation runs once setPaused lets it, which starts its running time
  // A controller that started the rig paused sends its schedule again after a reset, then unpauses.
  setPaused(options_.start_paused);
}

void RigSimulator::advertise() {
  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 100);
  load_cells_pub_ = nh_.advertise<geometry_msgs::WrenchStamped>("load_cells", 1000);
  gauges_pub_ = nh_.advertise<friction_msgs::StrainGaugeProfile>("strain_gauges", 1000);
  interface_pub_ = nh_.advertise<friction_msgs::InterfaceState>("interface", 10000);
  events_pub_ = nh_.advertise<friction_msgs::SlipEvent>("slip_events", 1000, true);
  lattice_pub_ = nh_.advertise<friction_msgs::LatticeSnapshot>("lattice", 2);
  stage_pub_ = nh_.advertise<friction_msgs::StageState>("stage_state", 100);
  applied_commands_pub_ = nh_.advertise<friction_msgs::StageCommand>("applied_commands", 100);
  command_sub_ = nh_.subscribe("stage_command", 1000, &RigSimulator::onCommand, this);
  command_srv_ = nh_.advertiseService("send_command", &RigSimulator::onSendCommand, this);
  pause_srv_ = nh_.advertiseService("pause", &RigSimulator::onPause, this);
  reset_srv_ = nh_.advertiseService("reset", &RigSimulator::onReset, this);
  stop_srv_ = nh_.advertiseService("stop", &RigSimulator::onStop, this);
  abort_srv_ = nh_.advertiseService("abort", &RigSimulator::onAbort, this);
  run_end_srv_ = nh_.advertiseService("set_run_end", &RigSimulator::onSetRunEnd, this);
  scene_pub_ = nh_.advertise<std_msgs::String>("scene", 1, true);
  publishScene();
}

void RigSimulator::publishScene() {
  // What is run, overrides applied and with the run's end as it stands, for whoever joins later and in
  // the bag: a recorded run can be analysed, played back or rerun offline with the scene it ran.
  std_msgs::String scene;
  scene.data = sceneToYaml(simulation_->scene());
  scene_pub_.publish(scene);
  if (bag_open_) {
    // Latched in the bag too, so that rosbag play latches it for whoever subscribes late. The first is
    // the bag's earliest message (1 ns: a bag cannot hold a zero stamp), a later one (a new run end) at
    // its time, after the first.
    auto header = boost::make_shared<ros::M_string>();
    (*header)["type"] = ros::message_traits::datatype(scene);
    (*header)["md5sum"] = ros::message_traits::md5sum(scene);
    (*header)["message_definition"] = ros::message_traits::definition(scene);
    (*header)["callerid"] = ros::this_node::getName();
    (*header)["latching"] = "1";
    const ros::Time earliest(0, scenes_recorded_ == 0 ? 1 : 2);
    bag_.write(scene_pub_.getTopic(), std::max(toStamp(simulation_->time()), earliest), scene, header);
    ++scenes_recorded_;
  }
}

template <class Message>
void RigSimulator::emit(ros::Publisher& publisher, const std::string& topic, const Message& msg) {
  publisher.publish(msg);
  // Before the first step (t = 0, e.g. the stage state while waiting paused) nothing was measured, and
  // a bag cannot hold a zero stamp.
  if (bag_open_ && !msg.header.stamp.isZero()) bag_.write(publisher.getTopic().empty() ? topic : publisher.getTopic(), msg.header.stamp, msg);
}

void RigSimulator::publishClock(double time) {
  rosgraph_msgs::Clock clock;
  clock.clock = toStamp(time);
  clock_pub_.publish(clock);
}

void RigSimulator::publishStageState() { publishStageState(simulation_->loadCells(), stageReading()); }

RigSimulator::StageReading RigSimulator::stageReading() const {
  const Stage& stage = simulation_->stage();
  return {stage.current().mode, stage.velocity(), stage.current().target, stage.travel()};
}

void RigSimulator::publishStageState(const LoadCellReading& cells, const StageReading& stage) {
  friction_msgs::StageState msg;
  msg.header.stamp = toStamp(cells.time);
  msg.header.frame_id = options_.frame_id;
  msg.mode = static_cast<std::uint8_t>(stage.mode);
  msg.position = cells.stage_position;
  msg.velocity = stage.velocity;
  msg.target = stage.target;
  msg.travel = stage.travel;
  msg.shear_force = cells.shear_force;
  msg.normal_force = cells.normal_force;
  msg.global_events = simulation_->globalEventCount();
  msg.paused = paused_;
  msg.resets = resets_;
  emit(stage_pub_, "stage_state", msg);
}

RigSimulator::Readings RigSimulator::readings() const {
  Readings now;
  now.cells = simulation_->loadCells();
  if (scene_.model == ModelKind::Lattice2D) now.gauges = simulation_->gaugeProfile();
  now.frame = simulation_->interfaceFrame();
  now.lattice = simulation_->snapshot();
  now.stage = stageReading();
  return now;
}

void RigSimulator::publishAcrossJump(const Readings& before) {
  const double t = simulation_->time();
  const Readings after = readings();
  const bool gauges = scene_.model == ModelKind::Lattice2D;
  // Each stream on its own grid, in time order within the stream.
  for (; next_clock_ <= t; next_clock_ += 1.0 / options_.clock_rate) publishClock(next_clock_);
  for (; next_load_cells_ <= t; next_load_cells_ += 1.0 / options_.load_cell_rate) {
    emit(load_cells_pub_, "load_cells", toMsg(interpolate(before.cells, after.cells, next_load_cells_), options_.frame_id));
  }
  for (; gauges && next_gauges_ <= t; next_gauges_ += 1.0 / options_.gauge_rate) {
    emit(gauges_pub_, "strain_gauges", toMsg(interpolate(before.gauges, after.gauges, next_gauges_), options_.frame_id));
  }
  // The whole interface sticks along a jump: the camera's idle rate.
  for (; next_frame_ <= t; next_frame_ += 1.0 / options_.interface_idle_rate) {
    emit(interface_pub_, "interface", toMsg(interpolate(before.frame, after.frame, next_frame_), frame_index_++, options_.frame_id));
  }
  for (; next_lattice_ <= t; next_lattice_ += 1.0 / options_.lattice_rate) {
    emit(lattice_pub_, "lattice", toMsg(interpolate(before.lattice, after.lattice, next_lattice_), options_.frame_id));
  }
  for (; next_stage_state_ <= t; next_stage_state_ += 1.0 / options_.stage_state_rate) {
    // The stage keeps its motion along a jump, which ends where it changes (a target reached, a segment
    // over): the motion of its start until its end, and a travel affine in time.
    StageReading stage = next_stage_state_ < t ? before.stage : after.stage;
    const double w = interpolationWeight(before.cells.time, after.cells.time, next_stage_state_);
    stage.travel = before.stage.travel + w * (after.stage.travel - before.stage.travel);
    publishStageState(interpolate(before.cells, after.cells, next_stage_state_), stage);
  }
}

void RigSimulator::publishInstruments() {
  const double t = simulation_->time();
  const std::string& frame = options_.frame_id;
  if (due(t, next_clock_, options_.clock_rate)) publishClock(t);
  const bool event_boundary = simulation_->eventStartedLastStep() || simulation_->eventEndedLastStep();
  if (due(t, next_load_cells_, options_.load_cell_rate) || event_boundary) {
    emit(load_cells_pub_, "load_cells", toMsg(simulation_->loadCells(), frame));
  }
  if (due(t, next_gauges_, options_.gauge_rate) && scene_.model == ModelKind::Lattice2D) {
    emit(gauges_pub_, "strain_gauges", toMsg(simulation_->gaugeProfile(), frame));
  }
  const double frame_rate = simulation_->inEvent() ? options_.interface_rate : options_.interface_idle_rate;
  if (simulation_->interfaceChangedLastStep() || t >= next_frame_) {
    emit(interface_pub_, "interface", toMsg(simulation_->interfaceFrame(), frame_index_++, frame));
    next_frame_ = t + 1.0 / frame_rate;
  }
  if (simulation_->eventEndedLastStep()) {
    emit(events_pub_, "slip_events",
         toMsg(simulation_->events().back(), interface_positions_, scene_.geometry.length, wave_speeds_, frame));
  }
  if (due(t, next_stage_state_, options_.stage_state_rate)) publishStageState();
  if (due(t, next_lattice_, options_.lattice_rate)) {
    emit(lattice_pub_, "lattice", toMsg(simulation_->snapshot(), frame));
  } else if (ros::WallTime::now() >= next_snapshot_ && lattice_pub_.getNumSubscribers() > 0) {
    // Live viewers also get snapshots at a visual rate; the bag keeps the simulated-time grid.
    lattice_pub_.publish(toMsg(simulation_->snapshot(), frame));
    next_snapshot_ = ros::WallTime::now() + ros::WallDuration(1.0 / options_.snapshot_rate);
  }
}

std::string RigSimulator::accept(const friction_msgs::StageCommand& msg) {
  std::string reason = checkCommand(msg, *simulation_);
  if (!reason.empty()) {
    ROS_WARN_STREAM("stage command refused: " << reason);
    return reason;
  }
  pending_.add(fromMsg(msg));
  return {};
}

void RigSimulator::applyDueCommands() {
  const double now = simulation_->time();
  pending_.applyDue(*simulation_, [&](const TimedCommand& command, const std::string& refusal) {
    if (!refusal.empty()) {
      ROS_WARN_STREAM("stage command refused: " << refusal);
      return;
    }
    if (command.time < now - simulation_->timeStep()) {
      ROS_DEBUG_STREAM("command for t = " << command.time << " s applied late, at " << now << " s");
    }
    friction_msgs::StageCommand applied = toMsg(command);
    applied.header.stamp = toStamp(now);
    applied.header.frame_id = options_.frame_id;
    applied_commands_pub_.publish(applied);
    // Unlike a measurement, a command at t = 0 matters: in the bag at its earliest time after the
    // scene's (1 ns), its stamp kept.
    if (bag_open_) bag_.write(applied_commands_pub_.getTopic(), std::max(applied.header.stamp, ros::Time(0, 2)), applied);
  });
}

void RigSimulator::onCommand(const friction_msgs::StageCommand::ConstPtr& msg) { accept(*msg); }

bool RigSimulator::onSendCommand(friction_msgs::SendStageCommand::Request& request,
                                 friction_msgs::SendStageCommand::Response& response) {
  response.reason = accept(request.command);
  response.accepted = response.reason.empty();
  return true;
}

bool RigSimulator::onPause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response) {
  setPaused(request.data);
  response.success = true;
  response.message = paused_ ? "paused" : "running";
  return true;
}

void RigSimulator::setPaused(bool paused) {
  const ros::WallTime now = ros::WallTime::now();
  if (paused && !paused_) running_wall_time_ += (now - running_since_).toSec();
  if (!paused && paused_) running_since_ = now;
  if (!paused) {
    pace_origin_wall_ = now;
    pace_origin_sim_ = simulation_->time();
  }
  paused_ = paused;
}

double RigSimulator::runningWallTime() const {
  return running_wall_time_ + (paused_ ? 0.0 : (ros::WallTime::now() - running_since_).toSec());
}

bool RigSimulator::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  reset_requested_ = true;
  response.success = true;
  response.message = "restarting the scene from its loaded equilibrium";
  return true;
}

bool RigSimulator::onStop(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  stop_ = true;
  response.success = true;
  response.message = "stopping at t = " + std::to_string(simulation_->time()) + " s";
  return true;
}

bool RigSimulator::onAbort(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response) {
  aborted_ = true;
  return onStop(request, response);
}

bool RigSimulator::onSetRunEnd(friction_msgs::SetRunEnd::Request& request, friction_msgs::SetRunEnd::Response& response) {
  StopSpec end;
  // Beyond int's range a count is never reached anyway.
  end.global_events = static_cast<int>(std::min<std::uint32_t>(request.global_events, std::numeric_limits<int>::max()));
  end.time = request.time;
  end.stage_travel = request.stage_travel;
  response.reason = simulation_->setStopCondition(end);
  response.accepted = response.reason.empty();
  if (response.accepted) {
    run_end_set_ = true;
    publishScene();
  } else {
    ROS_WARN_STREAM("run end refused: " << response.reason);
  }
  return true;
}

void RigSimulator::pace() {
  if (options_.real_time_factor <= 0.0) return;
  const double ahead = (simulation_->time() - pace_origin_sim_) / options_.real_time_factor -
                       (ros::WallTime::now() - pace_origin_wall_).toSec();
  if (ahead > 1e-3) ros::WallDuration(ahead).sleep();
}

void RigSimulator::run() {
  ros::WallTime next_spin = ros::WallTime::now();
  std::string end_reason;
  while (!stop_ && !g_stop_requested && ros::ok()) {
    const ros::WallTime now = ros::WallTime::now();
    if (now >= next_spin || paused_) {
      ros::spinOnce();
      next_spin = now + ros::WallDuration(0.002);
    }
    if (reset_requested_) {
      ++resets_;
      startSimulation();
      publishScene();  // the scene's own run end again
      continue;
    }
    if (paused_) {
      publishStageState();  // so that a controller learns the time and F_Z while the rig waits
      publishClock(simulation_->time());  // nodes on simulated time, and `rostopic echo /clock`, see it stand still
      if (lattice_pub_.getNumSubscribers() > 0) lattice_pub_.publish(toMsg(simulation_->snapshot(), options_.frame_id));
      ros::WallDuration(0.05).sleep();
      continue;
    }
    applyDueCommands();
    // A fast-forward jump stops at the next command, which changes the stage's motion. Run as fast as
    // possible it stops nowhere else and the instruments are interpolated across it: the jumps follow
    // the curved equilibrium path in straight pieces, so where they were cut would change the run, and
    // the offline runner's run of the same scene and commands is this one, step for step. Paced, it
    // also stops at each interface frame, so that a watcher sees the slider move and a command sent
    // "now" takes effect within a frame; its events may then differ from the unpaced run's by
    // fast-forward's own error. A rest with no end (the stage still, nothing due, no program segment
    // to end) is cut at frames too, or its jump would have no end. Not a rest that ends: each jump
    // solves the equilibrium afresh, so cutting one changes the run in its last digits (a hold of a
    // stop-and-go protocol, cut at 100 Hz, had made the events after it differ from the offline
    // runner's by 1e-12 to 1e-9; found by a new-user walkthrough).
    double until = pending_.nextTime();
    // A frame within a step of the command is no cut: the jump would stop a hair short of it, and the
    // step after would pass it (the command applied a step late, found by a new-user walkthrough).
    const Stage& stage = simulation_->stage();
    const bool endless_rest = stage.velocity() == 0.0 && pending_.empty() && std::isinf(stage.timeToNextChange());
    const bool cut_at_frames = options_.real_time_factor > 0.0 || endless_rest;
    if (cut_at_frames && next_frame_ < until - simulation_->timeStep()) until = next_frame_;
    const long long jumps = simulation_->jumps();
    // The readings before a possible jump, to interpolate across it; not needed for a plain step.
    const Readings before = simulation_->mayJump() ? readings() : Readings{};
    simulation_->advance(until);
    if (simulation_->jumps() != jumps) publishAcrossJump(before);
    publishInstruments();
    if ((options_.stop_at_scene_end || run_end_set_) && simulation_->finished()) {
      end_reason = simulation_->stopReason();
      ROS_INFO_STREAM("run ended: " << end_reason);
      break;
    }
    pace();
  }
  if (end_reason.empty()) {
    std::ostringstream reason;
    reason << (aborted_ ? "aborted by the abort service"
               : stop_  ? "stopped by the stop service"
               : g_stop_requested ? "interrupted by a signal" : "ROS shut down")
           << " at t = " << simulation_->time() << " s";
    end_reason = reason.str();
  }
  publishStageState();
  // The summary is the run since the last reset: its simulated time and steps start there, and its wall
  // time is the time spent running since, not waiting paused (for a controller, or a user).
  RunSummary summary = summarize(*simulation_, runningWallTime());
  summary.stop_reason = end_reason;
  printSummary(std::cout, summary);
  if (resets_ > 0) std::cout << "  (the run since the last of " << resets_ << " reset(s))" << std::endl;
  if (bag_open_) {
    bag_.close();
    bag_open_ = false;
    std::cout << "  bag written to " << options_.bag_path << std::endl;
  }
  // roscpp sends from its own thread: a node that exits at once can drop what it published last (the
  // last slip event, now that a run ends on the step of its last event).
  if (ros::ok()) ros::WallDuration(0.5).sleep();
}

}  // namespace friction
