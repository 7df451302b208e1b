#include "friction_sim/ros/rig_simulator.h"

#include <rosgraph_msgs/Clock.h>
#include <std_msgs/String.h>
#include <boost/make_shared.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "friction_sim/instruments/results_io.h"
#include "friction_sim/ros/node_parameters.h"
#include "friction_sim/scene/scene_io.h"

namespace friction {

std::atomic<bool> g_stop_requested{false};

namespace {
/// stage_command's subscriber queue: commands beyond it, unread, are dropped (and counted).
constexpr std::uint32_t kCommandQueue = 1000;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// ~bag_compression's names and the compressions they stand for.
const std::vector<std::pair<std::string, rosbag::compression::CompressionType>> kBagCompressions = {
    {"lz4", rosbag::compression::LZ4}, {"bz2", rosbag::compression::BZ2}, {"none", rosbag::compression::Uncompressed}};

/// The compression named by ~bag_compression, or none if the name is unknown.
std::optional<rosbag::compression::CompressionType> bagCompression(const std::string& name) {
  for (const auto& [known, compression] : kBagCompressions) {
    if (known == name) return compression;
  }
  return std::nullopt;
}
}  // namespace

const std::vector<std::pair<std::string, ros::Publisher RigSimulator::*>>& RigSimulator::waitablePublishers() {
  static const std::vector<std::pair<std::string, ros::Publisher RigSimulator::*>> publishers = {
      {"load_cells", &RigSimulator::load_cells_pub_},
      {"strain_gauges", &RigSimulator::gauges_pub_},
      {"interface", &RigSimulator::interface_pub_},
      {"slip_events", &RigSimulator::events_pub_},
      {"lattice", &RigSimulator::lattice_pub_},
      {"stage_state", &RigSimulator::stage_pub_},
      {"applied_commands", &RigSimulator::applied_commands_pub_},
      {"scene", &RigSimulator::scene_pub_}};
  return publishers;
}

ros::Publisher RigSimulator::*RigSimulator::publisherNamed(const std::string& topic) {
  for (const auto& [name, member] : waitablePublishers()) {
    if (name == topic) return member;
  }
  throw std::invalid_argument("no waitable topic " + topic);
}

std::vector<std::string> RigSimulator::waitableTopics() {
  std::vector<std::string> topics;
  for (const auto& publisher : waitablePublishers()) topics.push_back(publisher.first);
  return topics;
}

std::vector<std::pair<std::string, int>> parseAwaitedSubscribers(const std::string& text,
                                                                 std::vector<std::string>& problems) {
  const std::vector<std::string> topics = RigSimulator::waitableTopics();
  std::vector<std::pair<std::string, int>> awaited;
  std::istringstream items(text);
  std::string item;
  while (items >> item) {
    const std::size_t colon = item.find(':');
    const std::string topic = item.substr(0, colon);
    int count = 1;
    bool ok = std::find(topics.begin(), topics.end(), topic) != topics.end();
    if (ok && colon != std::string::npos) {
      std::size_t used = 0;
      try {
        count = std::stoi(item.substr(colon + 1), &used);
      } catch (const std::exception&) {
        used = 0;
      }
      ok = used > 0 && colon + 1 + used == item.size() && count >= 1;
    }
    if (!ok) {
      std::string allowed;
      for (const std::string& name : topics) allowed += (allowed.empty() ? "" : ", ") + name;
      problems.push_back("~wait_for_subscribers: item '" + item +
                         "' is not allowed; allowed: topic[:count] with a topic of " + allowed + " and a count >= 1");
      continue;
    }
    awaited.emplace_back(topic, count);
  }
  return awaited;
}

/// A publish rate: a live setting that allows only rates > 0.
constexpr LiveSetting rate(const char* name, double SimulatorConfig::*in_config, double SimulatorOptions::*in_options) {
  return {name, in_config, in_options, false, "a rate > 0 Hz"};
}

const LiveSettings kLiveSettings = {
    {{"real_time_factor", &SimulatorConfig::real_time_factor, &SimulatorOptions::real_time_factor, true,
      ">= 0 (0 = as fast as possible)"},
     rate("load_cell_rate", &SimulatorConfig::load_cell_rate, &SimulatorOptions::load_cell_rate),
     rate("gauge_rate", &SimulatorConfig::gauge_rate, &SimulatorOptions::gauge_rate),
     rate("gauge_idle_rate", &SimulatorConfig::gauge_idle_rate, &SimulatorOptions::gauge_idle_rate),
     rate("interface_rate", &SimulatorConfig::interface_rate, &SimulatorOptions::interface_rate),
     rate("interface_idle_rate", &SimulatorConfig::interface_idle_rate, &SimulatorOptions::interface_idle_rate),
     rate("stage_state_rate", &SimulatorConfig::stage_state_rate, &SimulatorOptions::stage_state_rate),
     rate("clock_rate", &SimulatorConfig::clock_rate, &SimulatorOptions::clock_rate),
     rate("lattice_rate", &SimulatorConfig::lattice_rate, &SimulatorOptions::lattice_rate),
     rate("lattice_idle_rate", &SimulatorConfig::lattice_idle_rate, &SimulatorOptions::lattice_idle_rate),
     rate("snapshot_rate", &SimulatorConfig::snapshot_rate, &SimulatorOptions::snapshot_rate)}};

std::vector<std::string> validateOptions(const SimulatorOptions& o) {
  std::vector<std::string> problems;
  auto require = [&](bool ok, const std::string& name, double value, const std::string& allowed) {
    requireSetting(ok, "~" + name, value, allowed, problems);
  };
  if (o.scene_path.empty()) problems.push_back("~scene: no value; allowed: the path of a scene YAML file");
  for (const LiveSetting& setting : kLiveSettings) {
    const double value = o.*setting.in_options;
    require(std::isfinite(value) && (value > 0.0 || (setting.zero_allowed && value == 0.0)), setting.name, value,
            setting.allowed);
  }
  if (o.frame_id.empty()) problems.push_back("~frame_id: empty; allowed: a frame name such as 'slider'");
  if (!bagCompression(o.bag_compression)) {
    std::string allowed;
    for (const auto& [name, compression] : kBagCompressions) allowed += (allowed.empty() ? "" : ", ") + name;
    problems.push_back("~bag_compression: value '" + o.bag_compression + "' is not allowed; allowed: " + allowed);
  }
  parseOverrides(o.overrides, problems);
  parseAwaitedSubscribers(o.wait_for_subscribers, problems);
  require(std::isfinite(o.subscriber_timeout) && o.subscriber_timeout > 0.0, "subscriber_timeout", o.subscriber_timeout,
          "> 0 s");
  require(o.threads >= 1, "threads", o.threads, "a whole number from 1");
  return problems;
}

SimulatorOptions readSimulatorOptions(const ros::NodeHandle& pnh) {
  SimulatorOptions o;
  ParameterReader reader(pnh);
  reader.read("scene", o.scene_path);
  reader.read("overrides", o.overrides);
  for (const LiveSetting& setting : kLiveSettings) reader.read(setting.name, o.*setting.in_options);
  reader.read("bag", o.bag_path);
  reader.read("bag_compression", o.bag_compression);
  reader.read("frame_id", o.frame_id);
  reader.read("stop_at_scene_end", o.stop_at_scene_end);
  reader.read("start_paused", o.start_paused);
  reader.read("wait_for_subscribers", o.wait_for_subscribers);
  reader.read("subscriber_timeout", o.subscriber_timeout);
  reader.read("threads", o.threads);
  reader.refuseIfAny(validateOptions(o));
  return o;
}

std::string checkCommand(const friction_msgs::StageCommand& msg, const RunDriver& driver) {
  if (msg.mode > friction_msgs::StageCommand::NORMAL_LOAD) {
    return "mode " + std::to_string(msg.mode) + " is unknown; allowed: 0 VELOCITY, 1 HOLD, 2 POSITION, 3 NORMAL_LOAD";
  }
  return driver.checkCommand(fromMsg(msg));
}

RigSimulator::RigSimulator(ros::NodeHandle nh, SimulatorOptions options)
    : nh_(std::move(nh)), options_(std::move(options)) {
  std::vector<std::string> problems;
  const auto overrides = parseOverrides(options_.overrides, problems);
  awaited_subscribers_ = parseAwaitedSubscribers(options_.wait_for_subscribers, problems);
  refuseParameters(problems);
  scene_ = loadScene(options_.scene_path, overrides, &stability_limit_);
  for (const std::string& warning : sceneWarnings(scene_)) ROS_WARN_STREAM("scene: " << warning);
  wave_speeds_ = waveSpeeds(scene_);
  // Opened before the run starts: a bag that cannot be written is refused rather than found out after
  // the loading solve, or lost at the end.
  if (!options_.bag_path.empty()) openBag();
  startSimulation();
  advertise();
}

RigSimulator::~RigSimulator() { closeBag(); }

void RigSimulator::openBag() {
  // As rosbag record does, the bag is written as BAG.active and renamed when closed: a bag under its
  // own name is complete. The lock on BAG.active keeps a second rig from writing the same bag.
  const std::string active = activeBagPath();
  auto refuse = [&](const std::string& why) {
    if (bag_lock_ >= 0) ::close(bag_lock_);
    bag_lock_ = -1;
    refuseParameters({"~bag: value '" + options_.bag_path + "' " + why});
  };
  bag_lock_ = ::open(active.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (bag_lock_ < 0) {
    refuse(std::string("cannot be written (") + std::strerror(errno) +
           "); allowed: a file path in a writable directory");
  }
  if (::flock(bag_lock_, LOCK_EX | LOCK_NB) != 0) {
    refuse("is being written by another rig (" + active + " is locked); allowed: a bag path no running rig writes");
  }
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(active, rosbag::bagmode::Write);
    bag->setCompression(*bagCompression(options_.bag_compression));
  } catch (const rosbag::BagException& error) {
    refuse(std::string("cannot be written (") + error.what() + "); allowed: a file path in a writable directory");
  }
  bag_ = std::move(bag);
}

void RigSimulator::closeBag() {
  if (bag_) {
    try {
      bag_->close();
      bag_.reset();
      const std::string active = activeBagPath();
      if (std::rename(active.c_str(), options_.bag_path.c_str()) != 0) {
        ROS_ERROR_STREAM("the bag stays at " << active << ": it could not be renamed (" << std::strerror(errno) << ")");
      }
    } catch (const rosbag::BagException& error) {
      abandonBag(error.what());
    }
  }
  if (bag_lock_ >= 0) {
    ::close(bag_lock_);
    bag_lock_ = -1;
  }
}

void RigSimulator::startSimulation() {
  RunOptions run;
  run.stop_at_scene_end = options_.stop_at_scene_end;
  // Paced, a watcher sees the slider move, and a command sent "now" acts within a frame.
  run.cut_jumps_at_frames = options_.real_time_factor > 0.0;
  run.threads = options_.threads;
  driver_ = std::make_unique<RunDriver>(scene_, stability_limit_, run);
  driver_->onCommandDue(
      [this](const TimedCommand& command, const std::string& refusal) { publishAppliedCommand(command, refusal); });
  addStreams(*driver_);
  interface_positions_ = simulation().model().interfacePositions();
  next_snapshot_ = ros::WallTime::now();
  reset_requested_ = false;
  running_wall_time_ = 0.0;
  paused_ = true;  // a new simulation runs once setPaused lets it, which starts its running time
  // A controller that started the rig paused sends its schedule again after a reset, then unpauses.
  setPaused(options_.start_paused);
}

void RigSimulator::addStreams(RunDriver& driver) {
  const SimulatorOptions& o = options_;
  clock_stream_ = &driver.add(std::make_unique<SampledStream<Instant>>(
      o.clock_rate, Sampling::AtSteps, [](const Simulation& s) { return Instant{s.time()}; },
      [this](const Instant& instant) { publishClock(instant.time); }));
  load_cells_stream_ = &driver.add(std::make_unique<SampledStream<LoadCellReading>>(
      o.load_cell_rate, Sampling::AtSteps, [](const Simulation& s) { return s.loadCells(); },
      [this](const LoadCellReading& cells) { emit(load_cells_pub_, "load_cells", toMsg(cells, options_.frame_id)); },
      true));
  gauges_stream_ = nullptr;
  if (scene_.model == ModelKind::Lattice2D) {
    gauges_stream_ = &driver.add(std::make_unique<SampledStream<GaugeProfile>>(
        SampleRates{o.gauge_rate, o.gauge_idle_rate}, Sampling::AtSteps,
        [](const Simulation& s) { return s.gaugeProfile(); },
        [this](const GaugeProfile& gauges) { emit(gauges_pub_, "strain_gauges", toMsg(gauges, options_.frame_id)); }));
  }
  camera_stream_ = &driver.add(std::make_unique<CameraStream>(
      SampleRates{o.interface_rate, o.interface_idle_rate}, [this](const InterfaceFrame& shot) {
        emit(interface_pub_, "interface", toMsg(shot, frame_index_++, options_.frame_id));
      }));
  driver.add(std::make_unique<EventStream>(nullptr, [this](const Simulation&, const SlipEvent& event) {
    emit(events_pub_, "slip_events",
         toMsg(event, interface_positions_, scene_.geometry.length, wave_speeds_, options_.frame_id));
  }));
  stage_stream_ = &driver.add(std::make_unique<SampledStream<StageStateReading>>(
      o.stage_state_rate, Sampling::AtSteps, stageState,
      [this](const StageStateReading& reading) { publishStageState(reading); }));
  lattice_stream_ = &driver.add(std::make_unique<SampledStream<LatticeSnapshot>>(
      SampleRates{o.lattice_rate, o.lattice_idle_rate}, Sampling::AtSteps,
      [](const Simulation& s) { return s.snapshot(); },
      [this](const LatticeSnapshot& snapshot) { emit(lattice_pub_, "lattice", toMsg(snapshot, options_.frame_id)); }));
}

void RigSimulator::onReconfigure(SimulatorConfig& config, std::uint32_t /*level*/) {
  SimulatorOptions live = options_;
  for (const LiveSetting& setting : kLiveSettings) live.*setting.in_options = config.*setting.in_config;
  const std::vector<std::string> problems = validateOptions(live);
  if (problems.empty()) {
    applyLiveSettings(live);
    return;
  }
  std::string reasons;
  for (const std::string& problem : problems) reasons += (reasons.empty() ? "" : "; ") + problem;
  ROS_WARN_STREAM("reconfigure refused, settings kept: " << reasons);
  for (const LiveSetting& setting : kLiveSettings) config.*setting.in_config = options_.*setting.in_options;
}

void RigSimulator::applyLiveSettings(const SimulatorOptions& live) {
  if (live.real_time_factor != options_.real_time_factor) {
    // The pace goes on from where the wall clock had brought it (from the simulation's time if unpaced),
    // at the new factor.
    pace_origin_sim_ = options_.real_time_factor > 0.0 ? pacedTime() : simulation().time();
    pace_origin_wall_ = ros::WallTime::now();
    driver_->setCutJumpsAtFrames(live.real_time_factor > 0.0);
    if (live.real_time_factor <= 0.0) releasePaced(kInfinity);
  }
  next_snapshot_ = std::min(next_snapshot_, ros::WallTime::now() + ros::WallDuration(1.0 / live.snapshot_rate));
  options_ = live;
  const double now = simulation().time();
  clock_stream_->setRates(SampleRates::uniform(live.clock_rate), now);
  load_cells_stream_->setRates(SampleRates::uniform(live.load_cell_rate), now);
  if (gauges_stream_) gauges_stream_->setRates({live.gauge_rate, live.gauge_idle_rate}, now);
  camera_stream_->setRates({live.interface_rate, live.interface_idle_rate}, now);
  stage_stream_->setRates(SampleRates::uniform(live.stage_state_rate), now);
  lattice_stream_->setRates({live.lattice_rate, live.lattice_idle_rate}, now);
}

void RigSimulator::advertise() {
  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 100);
  // Deep queues: an unpaced jump publishes all its interpolated samples at once (a 0.1 s jump, 10³ load
  // cells), and a full queue drops the oldest, which a subscriber busy elsewhere then never sees. At most
  // about 10 MB each (a gauge profile is some 1.2 kB, a load cell reading 0.1 kB).
  load_cells_pub_ = nh_.advertise<geometry_msgs::WrenchStamped>("load_cells", 100000);
  gauges_pub_ = nh_.advertise<friction_msgs::StrainGaugeProfile>("strain_gauges", 10000);
  interface_pub_ = nh_.advertise<friction_msgs::InterfaceState>("interface", 10000);
  events_pub_ = nh_.advertise<friction_msgs::SlipEvent>("slip_events", 1000, true);
  lattice_pub_ = nh_.advertise<friction_msgs::LatticeSnapshot>("lattice", 2);
  stage_pub_ = nh_.advertise<friction_msgs::StageState>("stage_state", 100);
  applied_commands_pub_ = nh_.advertise<friction_msgs::StageCommand>("applied_commands", 100);
  command_sub_ = nh_.subscribe("stage_command", kCommandQueue, &RigSimulator::onCommand, this);
  command_srv_ = nh_.advertiseService("send_command", &RigSimulator::onSendCommand, this);
  pause_srv_ = nh_.advertiseService("pause", &RigSimulator::onPause, this);
  reset_srv_ = nh_.advertiseService("reset", &RigSimulator::onReset, this);
  stop_srv_ = nh_.advertiseService("stop", &RigSimulator::onStop, this);
  abort_srv_ = nh_.advertiseService("abort", &RigSimulator::onAbort, this);
  run_end_srv_ = nh_.advertiseService("set_run_end", &RigSimulator::onSetRunEnd, this);
  scene_pub_ = nh_.advertise<std_msgs::String>("scene", 1, true);
  publishScene();
  // Its first values are the parameters as read (written back with their defaults).
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<SimulatorConfig>>(ros::NodeHandle("~"));
  reconfigure_->setCallback([this](SimulatorConfig& config, std::uint32_t level) { onReconfigure(config, level); });
}

void RigSimulator::publishScene() {
  // What is run, overrides applied and with the run's end as it stands, for whoever joins later and in
  // the bag: a recorded run can be analysed, played back or rerun offline with the scene it ran.
  std_msgs::String scene;
  scene.data = sceneToYaml(simulation().scene());
  scene_pub_.publish(scene);
  if (bag_) {
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
    record(scene_pub_.getTopic(), std::max(toStamp(simulation().time()), earliest), scene, header);
    ++scenes_recorded_;
  }
}

void RigSimulator::abandonBag(const std::string& why) {
  bag_failure_ = why;
  const std::string active = activeBagPath();
  ROS_ERROR_STREAM("the bag stays at " << active << ", without its index: `rosbag reindex " << active
                                       << "` recovers what was written");
  // Left open on purpose: rosbag's destructor would close it again, throw once more and end the process.
  static_cast<void>(bag_.release());
}

template <class Message>
void RigSimulator::record(const std::string& topic, const ros::Time& stamp, const Message& msg,
                          const boost::shared_ptr<ros::M_string>& header) {
  if (!bag_) return;
  try {
    bag_->write(topic, stamp, msg, header);
  } catch (const rosbag::BagException& error) {
    // A full disk, say: a run the user asked to record would go on unrecorded, so it ends here.
    ROS_ERROR_STREAM("the bag could not be written (" << error.what()
                                                      << "): the run ends at t = " << simulation().time() << " s");
    stop_ = true;
    abandonBag(error.what());
  }
}

template <class Message>
void RigSimulator::emit(ros::Publisher& publisher, const std::string& topic, const Message& msg) {
  publishPaced(msg.header.stamp.toSec(), [&publisher, msg] { publisher.publish(msg); });
  // Before the first step (t = 0, e.g. the stage state while waiting paused) nothing was measured, and
  // a bag cannot hold a zero stamp.
  if (!msg.header.stamp.isZero())
    record(publisher.getTopic().empty() ? topic : publisher.getTopic(), msg.header.stamp, msg);
}

void RigSimulator::publishClock(double time) {
  rosgraph_msgs::Clock clock;
  clock.clock = toStamp(time);
  publishPaced(time, [this, clock] { clock_pub_.publish(clock); });
}

void RigSimulator::publishStageState() { publishStageState(stageState(simulation())); }

void RigSimulator::publishStageState(const StageStateReading& reading) {
  const LoadCellReading& cells = reading.cells;
  const StageReading& stage = reading.stage;
  friction_msgs::StageState msg;
  msg.header.stamp = toStamp(cells.time);
  msg.header.frame_id = options_.frame_id;
  msg.mode = toMsgMode(stage.mode);
  msg.position = cells.stage_position;
  msg.velocity = stage.velocity;
  msg.target = stage.target;
  msg.travel = stage.travel;
  msg.shear_force = cells.shear_force;
  msg.normal_force = cells.normal_force;
  msg.global_events = simulation().globalEventCount();
  msg.paused = paused_;
  msg.resets = resets_;
  msg.commands_dropped = commands_dropped_;
  emit(stage_pub_, "stage_state", msg);
}

void RigSimulator::publishLiveSnapshot() {
  // Live viewers also get snapshots at a visual rate, also while paused (one who joins then sees the
  // slider); the bag keeps the simulated-time grid, and a step it sampled needs no other.
  if ((!paused_ && lattice_stream_->sampledLast()) || ros::WallTime::now() < next_snapshot_ ||
      lattice_pub_.getNumSubscribers() == 0) {
    return;
  }
  lattice_pub_.publish(toMsg(simulation().snapshot(), options_.frame_id));
  next_snapshot_ = ros::WallTime::now() + ros::WallDuration(1.0 / options_.snapshot_rate);
}

std::string RigSimulator::accept(const friction_msgs::StageCommand& msg) {
  const std::string reason = checkCommand(msg, *driver_);
  if (!reason.empty()) {
    ROS_WARN_STREAM("stage command refused: " << reason);
    return reason;
  }
  driver_->schedule(fromMsg(msg));
  return {};
}

void RigSimulator::publishAppliedCommand(const TimedCommand& command, const std::string& refusal) {
  if (!refusal.empty()) {
    ROS_WARN_STREAM("stage command refused: " << refusal);
    return;
  }
  const double now = simulation().time();
  if (command.time < now - simulation().timeStep()) {
    ROS_DEBUG_STREAM("command for t = " << command.time << " s applied late, at " << now << " s");
  }
  friction_msgs::StageCommand applied = toMsg(command);
  applied.header.stamp = toStamp(now);
  applied.header.frame_id = options_.frame_id;
  applied_commands_pub_.publish(applied);
  // Unlike a measurement, a command at t = 0 matters: in the bag at its earliest time after the
  // scene's (1 ns), its stamp kept.
  record(applied_commands_pub_.getTopic(), std::max(applied.header.stamp, ros::Time(0, 2)), applied);
}

void RigSimulator::onCommand(const ros::MessageEvent<const friction_msgs::StageCommand>& event) {
  // roscpp numbers every message a publisher sends (header.seq): a gap is messages that a full queue
  // dropped, here or in the publisher, before this callback saw them.
  const std::uint32_t seq = event.getMessage()->header.seq;
  const auto last = last_command_seq_.find(event.getPublisherName());
  if (last != last_command_seq_.end() && seq > last->second + 1) {
    const std::uint32_t dropped = seq - last->second - 1;
    commands_dropped_ += dropped;
    ROS_WARN_STREAM(dropped << " command(s) from " << event.getPublisherName() << " on " << command_sub_.getTopic()
                            << " were dropped unread: the queue of " << kCommandQueue << " was full ("
                            << commands_dropped_
                            << " so far); send them slower, or call send_command, which answers each");
  }
  last_command_seq_[event.getPublisherName()] = seq;
  accept(*event.getMessage());
}

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
  // Only on resuming: asked to run while running, the pace keeps its origin. Moved to the simulation's
  // time, which runs ahead of the wall clock, it would skip the messages held for their times.
  if (!paused && paused_) {
    running_since_ = now;
    pace_origin_wall_ = now;
    pace_origin_sim_ = simulation().time();
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
  response.message = "stopping at t = " + std::to_string(simulation().time()) + " s";
  return true;
}

bool RigSimulator::onAbort(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response) {
  aborted_ = true;
  return onStop(request, response);
}

bool RigSimulator::onSetRunEnd(friction_msgs::SetRunEnd::Request& request,
                               friction_msgs::SetRunEnd::Response& response) {
  StopSpec end;
  // Beyond int's range a count is never reached anyway.
  end.global_events = static_cast<int>(std::min<std::uint32_t>(request.global_events, std::numeric_limits<int>::max()));
  end.time = request.time;
  end.stage_travel = request.stage_travel;
  response.reason = driver_->setRunEnd(end);
  response.accepted = response.reason.empty();
  if (response.accepted) {
    publishScene();
  } else {
    ROS_WARN_STREAM("run end refused: " << response.reason);
  }
  return true;
}

void RigSimulator::publishPaced(double time, std::function<void()> publish) {
  if (options_.real_time_factor <= 0.0) {
    publish();
    return;
  }
  // Held with the rest, so that messages go out in the order of their times.
  paced_.emplace(time, std::move(publish));
  releasePaced(pacedTime());
}

double RigSimulator::pacedTime() const {
  return pace_origin_sim_ + (ros::WallTime::now() - pace_origin_wall_).toSec() * options_.real_time_factor;
}

void RigSimulator::releasePaced(double until) {
  while (!paced_.empty() && paced_.begin()->first <= until) {
    // Out of the queue before it runs: publishing may hold another message.
    const std::function<void()> publish = std::move(paced_.begin()->second);
    paced_.erase(paced_.begin());
    publish();
  }
}

void RigSimulator::pace() {
  // A step or a jump computes ahead of the wall clock: its messages go out as their simulated times come
  // due, not in a burst, and services and commands are answered meanwhile.
  constexpr double kSlice = 0.01;  // s of wall time between releases and spins
  while (!paused_ && !stop_ && !reset_requested_ && !g_stop_requested && ros::ok()) {
    // Unpaced from the start, or since a live change answered below.
    if (options_.real_time_factor <= 0.0) return;
    releasePaced(pacedTime());
    const double ahead = (simulation().time() - pacedTime()) / options_.real_time_factor;
    if (ahead <= 1e-3) return;
    ros::WallDuration(std::min(ahead, kSlice)).sleep();
    ros::spinOnce();
  }
}

void RigSimulator::run() {
  if (waitForSubscribers()) {
    finish(runUntilTheEnd());
    return;
  }
  subscribers_missing_ = true;
  finish("not started: subscribers missing");
}

bool RigSimulator::waitForSubscribers() {
  if (awaited_subscribers_.empty()) return true;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(options_.subscriber_timeout);
  while (!stop_ && !g_stop_requested && ros::ok()) {
    const std::string missing = missingSubscribers();
    if (missing.empty()) return true;
    if (ros::WallTime::now() >= deadline) {
      ROS_ERROR_STREAM("no run: after " << options_.subscriber_timeout << " s (~subscriber_timeout) still waiting "
                                        << "for subscribers of " << missing << " (~wait_for_subscribers)");
      return false;
    }
    ros::spinOnce();
    standStill();
  }
  return true;  // interrupted: the run loop ends at once, with the reason
}

void RigSimulator::standStill() {
  publishStageState();                // so that a controller learns the time and F_Z while the rig waits
  publishClock(simulation().time());  // nodes on simulated time, and `rostopic echo /clock`, see it stand still
  ros::WallDuration(0.05).sleep();
}

std::string RigSimulator::missingSubscribers() const {
  std::string missing;
  for (const auto& [topic, count] : awaited_subscribers_) {
    const ros::Publisher& publisher = this->*publisherNamed(topic);
    const int subscribers = static_cast<int>(publisher.getNumSubscribers());
    if (subscribers >= count) continue;
    missing += (missing.empty() ? "" : ", ") + publisher.getTopic() + " (" + std::to_string(subscribers) + " of " +
               std::to_string(count) + ")";
  }
  return missing;
}

std::string RigSimulator::runUntilTheEnd() {
  ros::WallTime next_spin = ros::WallTime::now();
  while (!stop_ && !g_stop_requested && ros::ok()) {
    const ros::WallTime now = ros::WallTime::now();
    if (now >= next_spin || paused_) {
      ros::spinOnce();
      next_spin = now + ros::WallDuration(0.002);
    }
    if (reset_requested_) {
      releasePaced(kInfinity);  // the old run's last messages, before the new run's
      ++resets_;
      startSimulation();
      publishScene();  // the scene's own run end again
      continue;
    }
    if (paused_) {
      publishLiveSnapshot();
      standStill();
      continue;
    }
    driver_->advance();
    publishLiveSnapshot();
    if (driver_->finished()) {
      ROS_INFO_STREAM("run ended: " << simulation().stopReason());
      return simulation().stopReason();
    }
    pace();
  }
  std::ostringstream reason;
  reason << (!bag_failure_.empty() ? "the bag could not be written (" + bag_failure_ + ")"
             : aborted_            ? "aborted by the abort service"
             : stop_               ? "stopped by the stop service"
             : g_stop_requested    ? "interrupted by a signal"
                                   : "ROS shut down")
         << " at t = " << simulation().time() << " s";
  return reason.str();
}

void RigSimulator::finish(const std::string& end_reason) {
  driver_->finishRun();
  publishStageState();
  releasePaced(kInfinity);
  // The summary is the run since the last reset: its simulated time and steps start there, and its wall
  // time is the time spent running since, not waiting paused (for a controller, or a user).
  RunSummary summary = summarize(simulation(), runningWallTime());
  summary.stop_reason = end_reason;
  printSummary(std::cout, summary);
  if (resets_ > 0) std::cout << "  (the run since the last of " << resets_ << " reset(s))" << std::endl;
  if (bag_) {
    closeBag();
    if (bag_failure_.empty()) std::cout << "  bag written to " << options_.bag_path << std::endl;
  }
  // roscpp sends from its own thread: a node that exits at once can drop what it published last (the
  // last slip event: a run ends on the step of its last event).
  if (ros::ok()) ros::WallDuration(0.5).sleep();
}

}  // namespace friction
