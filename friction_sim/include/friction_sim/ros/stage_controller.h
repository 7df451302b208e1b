// The loading-stage controller node: runs a loading protocol (friction_sim/loading_protocol.h) against
// the simulator through its topics and services only, so a user can replace it with their own node.
//
// Parameters (private, ~):
//   protocol (string, required)   path of the protocol YAML
//   start_delay (double, 1.0)     wall seconds to wait before starting a simulator that waits paused,
//                                 so that analysis nodes and recorders are connected from the first step
// Subscribed topics (relative to the node's namespace):
//   stage_state (friction_msgs/StageState)  simulated time, F_Z, stage travel, global event count
// Services called:
//   send_command (friction_msgs/SendStageCommand)  every scheduled command, stamped with its time; if the
//                                                   simulator refuses one, the controller aborts its run and
//                                                   exits with status 2 (the run would not be the protocol's)
//   set_run_end (friction_msgs/SetRunEnd)           the protocol's end, so that the simulator ends the run
//                                                   on the step where it is reached
//   pause (std_srvs/SetBool)                        called with false once the schedule is sent, so
//                                                   that a simulator started paused runs every command on
//                                                   time; if the call fails, the controller aborts the run
//   stop (std_srvs/Trigger)                         once an end condition of the protocol holds, if the
//                                                   simulator did not take it through set_run_end
//   abort (std_srvs/Trigger)                        when the protocol, a parameter or a command is refused,
//                                                   or the simulator cannot be unpaused:
//                                                   the simulator ends its run and exits with status 4, the
//                                                   node with status 2, the problems listed
//
// Uses ROS time only (the stage state's stamps, i.e. simulated time). If time jumps backwards or the
// stage state's reset count changes (a reset), it starts the protocol again from the new time.
#pragma once

#include <friction_msgs/SendStageCommand.h>
#include <friction_msgs/StageState.h>
#include <ros/ros.h>

#include <cstdint>

#include <string>
#include <vector>

#include "friction_sim/scene/loading_protocol.h"

namespace friction {

struct ControllerOptions {
  std::string protocol_path;  ///< path of the protocol YAML
  /// s of wall time to wait before starting a simulator that waits paused (analysis nodes and recorders
  /// connect meanwhile)
  double start_delay = 1.0;
};

/// Every problem of the options, each naming the parameter, the value and the allowed range.
std::vector<std::string> validateControllerOptions(const ControllerOptions& options);
/// Reads the options from the private parameters; throws ConfigError listing every problem.
ControllerOptions readControllerOptions(const ros::NodeHandle& private_nh);

/// Calls the simulator's `service` in `nh`'s namespace, "stop" (end the run) or "abort" (end it as
/// failed), waiting up to `wait` for it to appear; false if it did not or the call failed.
bool endSimulatorRun(ros::NodeHandle& nh, const std::string& service, ros::WallDuration wait);

class StageController {
 public:
  StageController(ros::NodeHandle nh, LoadingProtocol protocol, double start_delay);
  /// The simulator refused a command of the protocol, could not be reached or could not be unpaused: the
  /// node has aborted its run and shut down.
  bool failed() const { return failed_; }

 private:
  void onStageState(const friction_msgs::StageState::ConstPtr& msg);
  void start(double time, double normal_force);
  /// Connects to send_command once it exists, waiting at most `wait` (negative: for ever).
  bool connectCommands(ros::Duration wait);
  /// Calls send_command, once more on a new connection if the call fails; false if both failed.
  bool sendCommand(friction_msgs::SendStageCommand& call);
  /// Logs `why`, calls the simulator's abort and shuts the node down (failed()).
  void abortRun(const std::string& why);

  ros::NodeHandle nh_;
  LoadingProtocol protocol_;
  double start_delay_;
  ros::Subscriber state_sub_;
  ros::ServiceClient command_client_, pause_client_, run_end_client_;
  bool failed_ = false;
  bool simulator_ends_run_ = false;  ///< the simulator took the protocol's end (set_run_end)
  std::uint32_t resets_seen_ = 0;    ///< the simulator's reset count in the last stage_state
  bool started_ = false;
  bool ended_ = false;
  double start_time_ = 0.0;
  double last_time_ = 0.0;
};

}  // namespace friction
