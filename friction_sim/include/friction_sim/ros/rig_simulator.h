// The rig simulator node: runs a scene and publishes what the lab's instruments measure.
//
// Parameters (private, ~):
//   scene (string, required)        path of the scene YAML (the offline runner's format)
//   overrides (string, "")          scene fields to replace, "key=value key=value" (e.g. "pusher.height=0.01")
//   The pace and the rates (real_time_factor to snapshot_rate) can also be changed while the rig runs,
//   with dynamic_reconfigure (~set_parameters, `rosrun dynamic_reconfigure dynparam set`); a change is
//   checked as the parameters are, and a bad one is refused with a logged reason, the settings kept.
//   real_time_factor (double, 0)    simulated seconds per wall second; 0 runs as fast as possible
//   load_cell_rate (double, 1e4)    Hz of simulated time, load_cells
//   gauge_rate (double, 1e5)        Hz of simulated time, strain_gauges during slip events
//   gauge_idle_rate (double, 1e3)   Hz of simulated time, strain_gauges while all is stuck
//   interface_rate (double, 1e5)    Hz of simulated time, interface frames during slip events
//   interface_idle_rate (double, 100)  Hz of simulated time, interface frames while all is stuck
//   stage_state_rate (double, 1e3)  Hz of simulated time, stage_state
//   clock_rate (double, 1e4)        Hz of simulated time, /clock
//   lattice_rate (double, 1e4)      Hz of simulated time, lattice snapshots during slip events (also
//                                   written to the bag)
//   lattice_idle_rate (double, 50)  Hz of simulated time, lattice snapshots while all is stuck
//   snapshot_rate (double, 20)      Hz of wall time, extra lattice snapshots while someone watches live
//   bag (string, "")                write every instrument topic to this bag, independent of subscribers;
//                                   written as BAG.active (locked: a second rig is refused) and renamed
//                                   when closed, as rosbag record does
//   bag_compression (string, "lz4") the bag's chunks: "lz4", "bz2" or "none" (docs/ros_api.md: sizes)
//   frame_id (string, "slider")     frame of every message
//   stop_at_scene_end (bool, true)  end when the scene's stop condition holds
//   start_paused (bool, false)      wait at t = 0 until `pause` is called with false (a controller
//                                   sends its schedule first, so every command is on time)
//   wait_for_subscribers (string, "")  wait at t = 0 until these topics have subscribers: "topic[:count]
//                                   ...", topics of the list below by their relative names (e.g.
//                                   "load_cells interface:2 slip_events"), a count of 1 if not given; so
//                                   that a recorder or an analysis node started with the rig sees the run
//                                   from its start
//   subscriber_timeout (double, 30) s of wall time to wait for them; then the node logs the topics still
//                                   short of subscribers and exits with status 5, the run not started.
//                                   stop and abort are answered while it waits
//   threads (int, 1)                threads for the 2D lattice's force sweeps, used from 10³ nodes; the
//                                   same results for any count
//
// Published topics (relative to the node's namespace; stamps are simulated time):
//   /clock (rosgraph_msgs/Clock)                   simulated time; at 20 Hz of wall time while paused
//   load_cells (geometry_msgs/WrenchStamped)       force on the slider: F_X in force.x, −F_Z in force.z
//   strain_gauges (friction_msgs/StrainGaugeProfile)
//   interface (friction_msgs/InterfaceState)       also at every step where a node unsticks or an event ends
//   slip_events (friction_msgs/SlipEvent, latched) when an event ends
//   lattice (friction_msgs/LatticeSnapshot)
//   stage_state (friction_msgs/StageState)
//   scene (std_msgs/String, latched)               the scene as run, overrides applied, in the scene YAML
//                                                  format (also the bag's first message); again with its
//                                                  stop condition replaced when set_run_end is accepted,
//                                                  and as it was after a reset
//   applied_commands (friction_msgs/StageCommand)  every command as it took effect, stamped with the
//                                                  simulated time of the step it took effect at: with the
//                                                  scene, the bag's record of what drove the run (rig_report
//                                                  writes both out, and friction_run --commands reruns them)
// Across a fast-forward jump each stream is interpolated on its own grid (the camera, the gauges and the
// lattice at their idle rates): the jump is cut only where a command is due, so that the run is the offline
// runner's, step for step; paced (real_time_factor > 0) also at every interface frame, so that a watcher
// sees the slider move and a command sent "now" acts within a frame; and while the stage rests with no
// end in sight (nothing due, no program segment to end), whose jumps would have no end.
// Subscribed topics:
//   stage_command (friction_msgs/StageCommand)     applied at header.stamp (simulated time); commands lost
//                                                  to a full queue (1000) are counted from the gaps in each
//                                                  publisher's header.seq, logged, and reported in
//                                                  stage_state.commands_dropped
// Services:
//   send_command (friction_msgs/SendStageCommand)  the same, with the verdict in the reply
//   set_run_end (friction_msgs/SetRunEnd)         ends the run at the first step where a count of global
//                                                  events, a simulated time or a stage travel is reached,
//                                                  in place of the scene's stop condition and of
//                                                  ~stop_at_scene_end (a controller's end of its protocol,
//                                                  so that a run ends where it should however fast it runs);
//                                                  a condition already met is refused (call stop)
//   pause (std_srvs/SetBool), reset (std_srvs/Trigger), stop (std_srvs/Trigger)
//   ~set_parameters (dynamic_reconfigure/Reconfigure)  the pace and the rates, live (above); with
//                                                  ~parameter_descriptions and ~parameter_updates
//   abort (std_srvs/Trigger)                       ends the run as stop does, and the node then exits with
//                                                  status 4: what drives the run could not (a controller
//                                                  whose protocol or command was refused)
//   A reset restarts the scene from t = 0 with the scene's stop condition, paused if ~start_paused; the
//   summary printed when the node ends is then the run since the last reset. Its wall time is the time
//   spent running, not waiting paused.
// Exit status: 0 when the run ended (its end, stop, a signal, ROS shut down), 2 when the scene or a
// parameter is refused, 3 when the bag could not be written (the run ends there, the bag keeping what
// was written), 4 when the run was aborted, 5 when ~wait_for_subscribers' subscribers did not come
// within ~subscriber_timeout.
//
// A command that checkCommand refuses (NaN/inf, a normal load out of range or
// under a spring mattress, a speed beyond stage.max_speed, a POSITION speed <= 0, a stamp after the run's
// known end, an unknown mode) is refused with a logged reason; the simulation keeps running. A HOLD's
// speed and target are ignored: a hold has none.
#pragma once

#include <dynamic_reconfigure/server.h>
#include <friction_msgs/SendStageCommand.h>
#include <friction_msgs/SetRunEnd.h>
#include <friction_msgs/StageCommand.h>
#include <friction_sim/SimulatorConfig.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "friction_sim/ros/conversions.h"
#include "friction_sim/run/run_driver.h"
#include "friction_sim/scene/loading_protocol.h"

namespace friction {

struct SimulatorOptions {
  std::string scene_path;               ///< path of the scene YAML
  std::string overrides;                ///< "key=value ..." scene fields to replace
  double real_time_factor = 0.0;        ///< sim s per wall s; 0 = as fast as possible
  double load_cell_rate = 1e4;          ///< Hz, simulated
  double gauge_rate = 1e5;              ///< Hz, simulated, during events
  double gauge_idle_rate = 1e3;         ///< Hz, simulated, while all is stuck
  double interface_rate = 1e5;          ///< Hz, simulated, during events
  double interface_idle_rate = 100.0;   ///< Hz, simulated, while all is stuck
  double stage_state_rate = 1e3;        ///< Hz, simulated
  double clock_rate = 1e4;              ///< Hz, simulated
  double lattice_rate = 1e4;            ///< Hz, simulated, during events
  double lattice_idle_rate = 50.0;      ///< Hz, simulated, while all is stuck
  double snapshot_rate = 20.0;          ///< Hz, wall
  std::string bag_path;                 ///< "" = no bag
  std::string bag_compression = "lz4";  ///< "lz4", "bz2" or "none": how the bag's chunks are compressed
  std::string frame_id = "slider";      ///< frame of every message, the slider's (x along the track, z up)
  bool stop_at_scene_end = true;        ///< end the run when the scene's stop condition holds
  bool start_paused = false;            ///< wait at t = 0 until `pause` is called with false
  std::string wait_for_subscribers;     ///< "topic[:count] ...": wait at t = 0 until they subscribe
  double subscriber_timeout = 30.0;     ///< s of wall time to wait for them
  int threads = 1;                      ///< threads for the force sweeps (RunOptions::threads)
};

using SimulatorConfig = friction_sim::SimulatorConfig;
/// A setting dynamic_reconfigure changes live (cfg/Simulator.cfg): its parameter's name, its field in the
/// config and in the options, and the values it allows (finite, > 0, or also 0 where `zero_allowed`).
struct LiveSetting {
  const char* name;
  double SimulatorConfig::*in_config;
  double SimulatorOptions::*in_options;
  bool zero_allowed;
  const char* allowed;
};
/// The pace, then the rates: read, checked and changed live through this one list.
using LiveSettings = std::array<LiveSetting, 11>;
extern const LiveSettings kLiveSettings;

/// ~wait_for_subscribers parsed: each topic (relative name) with its count; a problem for each bad item.
std::vector<std::pair<std::string, int>> parseAwaitedSubscribers(const std::string& text,
                                                                 std::vector<std::string>& problems);

/// Every problem of the options, each naming the parameter, the value and the allowed range.
std::vector<std::string> validateOptions(const SimulatorOptions& options);
/// Reads the options from the private parameters; throws ConfigError listing every problem.
SimulatorOptions readSimulatorOptions(const ros::NodeHandle& private_nh);
/// Why a command must be refused (empty = acceptable): an unknown mode, then what `driver` refuses
/// (RunDriver::checkCommand: the simulation, then the run's end).
std::string checkCommand(const friction_msgs::StageCommand& msg, const RunDriver& driver);

/// Set by SIGINT/SIGTERM: the node finishes its bag and exits.
extern std::atomic<bool> g_stop_requested;

class RigSimulator {
 public:
  /// Loads the scene (throws SceneError/ConfigError before anything is advertised).
  RigSimulator(ros::NodeHandle nh, SimulatorOptions options);
  ~RigSimulator();
  /// Runs until the scene ends, `stop` or `abort` is called, the node is shut down or a signal arrives.
  void run();
  /// The run was ended by the `abort` service.
  bool aborted() const { return aborted_; }
  /// The bag could not be written (the run ended there) or closed.
  bool bagFailed() const { return !bag_failure_.empty(); }
  /// The run never started: ~wait_for_subscribers' subscribers did not come in time.
  bool subscribersMissing() const { return subscribers_missing_; }
  /// The topics ~wait_for_subscribers may name, relative to the node's namespace.
  static std::vector<std::string> waitableTopics();

 private:
  /// The publishers ~wait_for_subscribers may name, by their topics' relative names.
  static const std::vector<std::pair<std::string, ros::Publisher RigSimulator::*>>& waitablePublishers();
  /// The publisher of a waitable topic (one parseAwaitedSubscribers accepted).
  static ros::Publisher RigSimulator::*publisherNamed(const std::string& topic);
  /// Waits at t = 0, answering services, until ~wait_for_subscribers holds; false if its timeout passed.
  bool waitForSubscribers();
  /// While the rig stands at its time (paused, or waiting for subscribers): the stage state and the clock,
  /// then 50 ms of wall time.
  void standStill();
  /// "topic (n of m)" for each awaited topic short of its subscribers; empty once all have them.
  std::string missingSubscribers() const;
  /// Spins, pauses, resets, advances and paces until the run ends; returns why it ended.
  std::string runUntilTheEnd();
  /// The stage state, the summary and the bag at the end of the run.
  void finish(const std::string& end_reason);
  void advertise();
  /// BAG.active: where the bag is written until it is closed.
  std::string activeBagPath() const { return options_.bag_path + ".active"; }
  /// Opens ~bag as BAG.active, locked against a second writer; throws ConfigError if it cannot.
  void openBag();
  /// Closes the bag and renames it to its own name, then drops the lock; a bag whose index cannot be
  /// written is abandoned.
  void closeBag();
  /// After a failed write or close: the bag stays at BAG.active, unclosed and without its index, and the
  /// failure is logged with the way to recover what was written.
  void abandonBag(const std::string& why);
  void startSimulation();
  /// The scene as it runs now (its stop condition set_run_end's, if called) on `scene` and in the bag.
  void publishScene();
  /// The instruments' streams of a new run, each publishing to its topic.
  void addStreams(RunDriver& driver);
  /// A lattice snapshot at the wall-clock rate for live viewers, when the bag's clock gave none.
  void publishLiveSnapshot();
  void publishClock(double time);
  void publishStageState(const StageStateReading& reading);
  /// The stage state now.
  void publishStageState();
  void publishAppliedCommand(const TimedCommand& command, const std::string& refusal);
  std::string accept(const friction_msgs::StageCommand& msg);
  void onCommand(const ros::MessageEvent<const friction_msgs::StageCommand>& event);
  bool onSendCommand(friction_msgs::SendStageCommand::Request& request,
                     friction_msgs::SendStageCommand::Response& response);
  bool onPause(std_srvs::SetBool::Request& request, std_srvs::SetBool::Response& response);
  bool onReset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onStop(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onAbort(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onSetRunEnd(friction_msgs::SetRunEnd::Request& request, friction_msgs::SetRunEnd::Response& response);
  /// Sleeps until the wall clock reaches the simulation's time (paced runs), releasing the messages
  /// held for their times and answering services every 10 ms.
  void pace();
  /// Publishes now, or, in a paced run, when the wall clock reaches simulated time `time` (s).
  void publishPaced(double time, std::function<void()> publish);
  /// s, the simulated time the wall clock has reached in a paced run.
  double pacedTime() const;
  /// Publishes the held messages due by simulated time `until` (s), in time order.
  void releasePaced(double until);
  /// Pauses or runs the simulation, keeping the pace's origin and the wall time spent running.
  void setPaused(bool paused);
  /// s of wall time spent running (not paused) since the simulation last started.
  double runningWallTime() const;
  /// Writes `msg` to the bag, if one is open; if it cannot be written, logs why, ends the run and closes it.
  template <class Message>
  void record(const std::string& topic, const ros::Time& stamp, const Message& msg,
              const boost::shared_ptr<ros::M_string>& header = {});
  /// Publishes `msg` (paced) on `publisher` and records it under its topic (`topic` before it is advertised).
  template <class Message>
  void emit(ros::Publisher& publisher, const std::string& topic, const Message& msg);

  /// dynamic_reconfigure's callback: the pace and the rates, checked as the parameters are; a refused
  /// change is logged and `config` set back to the settings kept.
  void onReconfigure(SimulatorConfig& config, std::uint32_t level);
  /// Takes `live`'s pace and rates (validated) into the run under way; a reset keeps them.
  void applyLiveSettings(const SimulatorOptions& live);

  ros::NodeHandle nh_;
  SimulatorOptions options_;
  Scene scene_;
  double stability_limit_ = 0.0;  ///< s, of scene_, from its validation
  const Simulation& simulation() const { return driver_->simulation(); }
  std::unique_ptr<RunDriver> driver_;  ///< the run since the start or the last reset
  // driver_'s streams, for their rates; gauges_stream_ is null on a chain (no gauges).
  SampledStream<Instant>* clock_stream_ = nullptr;
  SampledStream<LoadCellReading>* load_cells_stream_ = nullptr;
  SampledStream<GaugeProfile>* gauges_stream_ = nullptr;
  CameraStream* camera_stream_ = nullptr;
  SampledStream<StageStateReading>* stage_stream_ = nullptr;
  SampledStream<LatticeSnapshot>* lattice_stream_ = nullptr;
  std::unique_ptr<dynamic_reconfigure::Server<SimulatorConfig>> reconfigure_;
  std::vector<double> interface_positions_;
  WaveSpeeds wave_speeds_;
  std::unique_ptr<rosbag::Bag> bag_;  ///< the bag while the run is recorded (~bag); null otherwise
  std::string bag_failure_;           ///< why the bag could not be written or closed; empty while it can
  int bag_lock_ = -1;                 ///< descriptor holding the flock on BAG.active while this rig writes the bag
  bool paused_ = false;
  bool stop_ = false;
  bool aborted_ = false;
  bool subscribers_missing_ = false;
  std::vector<std::pair<std::string, int>> awaited_subscribers_;  ///< ~wait_for_subscribers, parsed
  bool reset_requested_ = false;
  int scenes_recorded_ = 0;   ///< scene messages written to the bag
  std::uint32_t resets_ = 0;  ///< resets so far, in stage_state: a controller cannot always tell one by the time
  std::uint32_t frame_index_ = 0;
  std::map<std::string, std::uint32_t> last_command_seq_;  ///< per publisher of stage_command, its last header.seq
  std::uint32_t commands_dropped_ = 0;                     ///< stage_command messages lost to a full queue
  ros::WallTime next_snapshot_, pace_origin_wall_;
  double running_wall_time_ = 0.0;  ///< s, wall time spent running before running_since_
  ros::WallTime running_since_;     ///< when the simulation last began running (unpaused)
  double pace_origin_sim_ = 0.0;
  std::multimap<double, std::function<void()>> paced_;  ///< messages held for their simulated times (s)
  ros::Publisher clock_pub_, load_cells_pub_, gauges_pub_, interface_pub_, events_pub_, lattice_pub_, stage_pub_,
      scene_pub_, applied_commands_pub_;
  ros::Subscriber command_sub_;
  ros::ServiceServer command_srv_, pause_srv_, reset_srv_, stop_srv_, abort_srv_, run_end_srv_;
};

}  // namespace friction
