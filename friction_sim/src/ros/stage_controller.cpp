#include "friction_sim/ros/stage_controller.h"

#include <friction_msgs/SendStageCommand.h>
#include <friction_msgs/SetRunEnd.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>

#include <cmath>
#include <cstdint>

#include "friction_sim/ros/conversions.h"
#include "friction_sim/ros/node_parameters.h"
#include "friction_sim/scene/config_error.h"

namespace friction {

std::vector<std::string> validateControllerOptions(const ControllerOptions& options) {
  std::vector<std::string> problems;
  if (options.protocol_path.empty())
    problems.push_back("~protocol: no value; allowed: the path of a protocol YAML file");
  requireSetting(std::isfinite(options.start_delay) && options.start_delay >= 0.0, "~start_delay", options.start_delay,
                 ">= 0 s", problems);
  return problems;
}

ControllerOptions readControllerOptions(const ros::NodeHandle& private_nh) {
  ControllerOptions options;
  ParameterReader reader(private_nh);
  reader.read("protocol", options.protocol_path);
  reader.read("start_delay", options.start_delay);
  reader.refuseIfAny(validateControllerOptions(options));
  return options;
}

bool endSimulatorRun(ros::NodeHandle& nh, const std::string& service, ros::WallDuration wait) {
  ros::ServiceClient client = nh.serviceClient<std_srvs::Trigger>(service);
  std_srvs::Trigger call;
  return client.waitForExistence(ros::Duration(wait.toSec())) && client.call(call);
}

StageController::StageController(ros::NodeHandle nh, LoadingProtocol protocol, double start_delay)
    : nh_(std::move(nh)), protocol_(std::move(protocol)), start_delay_(start_delay) {
  pause_client_ = nh_.serviceClient<std_srvs::SetBool>("pause");
  run_end_client_ = nh_.serviceClient<friction_msgs::SetRunEnd>("set_run_end");
  state_sub_ = nh_.subscribe("stage_state", 100, &StageController::onStageState, this);
}

bool StageController::connectCommands(ros::Duration wait) {
  // Persistent: a protocol's few dozen commands go over one connection, not one lookup and one
  // connection each. Made once the service exists: a persistent client that found none stays invalid.
  if (!ros::service::waitForService(nh_.resolveName("send_command"), wait)) return false;
  command_client_ = nh_.serviceClient<friction_msgs::SendStageCommand>("send_command", true);
  return true;
}

bool StageController::sendCommand(friction_msgs::SendStageCommand& call) {
  if (command_client_.call(call)) return true;
  // Once more over a new connection before the command counts as lost: a persistent link ends when the
  // simulator's node restarts, and a call can fail on a loaded machine. If the failed call did reach the
  // simulator, it now holds the command twice, which is harmless: a command says what to do and when
  // (a speed, a target, an F_Z at a simulated time), not by how much to change.
  ROS_WARN("stage controller: send_command failed; reconnecting");
  return connectCommands(ros::Duration(5.0)) && command_client_.call(call);
}

void StageController::start(double time, double normal_force) {
  started_ = true;
  ended_ = false;
  start_time_ = time;
  // Waits for the simulator; fails only when ROS shuts down.
  if (!command_client_.isValid() && !connectCommands(ros::Duration(-1))) return;
  int refused = 0;
  for (const TimedCommand& command : scheduleProtocol(protocol_, time, normal_force)) {
    friction_msgs::SendStageCommand call;
    call.request.command = toMsg(command);
    if (!sendCommand(call)) {
      ROS_ERROR("stage controller: send_command failed (is the simulator running?)");
      ++refused;
    } else if (!call.response.accepted) {
      ROS_ERROR_STREAM("stage controller: command for t = " << command.time << " s refused: " << call.response.reason);
      ++refused;
    }
  }
  if (refused > 0) {
    // The run would not be the protocol's: the simulator would go on under what it had before.
    abortRun(std::to_string(refused) + " command(s) of the protocol refused");
    return;
  }
  // The simulator ends the run itself at the protocol's end, on the step where it is reached; where it
  // refuses that end, the watch in onStageState stops it.
  const StopSpec run_end = protocol_.end.stopFrom(time);
  friction_msgs::SetRunEnd end;
  end.request.global_events = static_cast<std::uint32_t>(run_end.global_events);
  end.request.time = run_end.time;
  end.request.stage_travel = run_end.stage_travel;
  simulator_ends_run_ = run_end_client_.call(end) && end.response.accepted;
  if (!simulator_ends_run_) {
    ROS_WARN_STREAM("stage controller: the simulator did not take the protocol's end ("
                    << (end.response.reason.empty() ? "no set_run_end service" : end.response.reason)
                    << "); it will be stopped when the end is seen");
  }
  ros::WallDuration(start_delay_).sleep();
  std_srvs::SetBool run;
  run.request.data = false;
  if (!pause_client_.call(run)) {
    // Left paused, the simulator would wait for ever with the protocol scheduled.
    abortRun("the simulator could not be unpaused (pause failed)");
    return;
  }
  ROS_INFO_STREAM("stage controller: protocol started at t = " << time << " s");
}

void StageController::abortRun(const std::string& why) {
  ROS_ERROR_STREAM("stage controller: " << why << "; aborting the run");
  failed_ = true;
  endSimulatorRun(nh_, "abort", ros::WallDuration(5.0));
  ros::shutdown();
}

void StageController::onStageState(const friction_msgs::StageState::ConstPtr& msg) {
  const double time = msg->header.stamp.toSec();
  // A reset shows as a new count, also when it comes before time has moved on (while the controller
  // waits to unpause), where the time alone would not show it.
  if (started_ && (time < last_time_ || msg->resets != resets_seen_)) {
    ROS_WARN_STREAM("stage controller: the simulation restarted (t = " << time << " s, " << msg->resets
                                                                       << " resets); restarting the protocol");
    started_ = false;
  }
  last_time_ = time;
  resets_seen_ = msg->resets;
  if (!started_) start(time, msg->normal_force);
  if (failed_) return;
  if (ended_ ||
      !stopReached(protocol_.end.stopFrom(start_time_), static_cast<int>(msg->global_events), time, msg->travel)) {
    return;
  }
  ended_ = true;
  ROS_INFO_STREAM("stage controller: protocol ended at t = "
                  << time << " s after " << msg->global_events << " global events"
                  << (simulator_ends_run_ ? "" : "; stopping the simulator"));
  if (!simulator_ends_run_) endSimulatorRun(nh_, "stop", ros::WallDuration(5.0));
  ros::shutdown();
}

}  // namespace friction
