#include "friction_rviz/commands.h"

namespace friction_rviz {

namespace {
// A zero stamp means "apply now" to the simulator.
friction_msgs::StageCommand command(std::uint8_t mode) {
  friction_msgs::StageCommand msg;
  msg.mode = mode;
  return msg;
}
}  // namespace

friction_msgs::StageCommand driveCommand(double speed_mm_per_s) {
  auto msg = command(friction_msgs::StageCommand::VELOCITY);
  msg.speed = speed_mm_per_s * 1e-3;
  return msg;
}

friction_msgs::StageCommand holdCommand() { return command(friction_msgs::StageCommand::HOLD); }

friction_msgs::StageCommand moveCommand(double target_mm, double speed_mm_per_s) {
  auto msg = command(friction_msgs::StageCommand::POSITION);
  msg.target = target_mm * 1e-3;
  msg.speed = speed_mm_per_s * 1e-3;
  return msg;
}

friction_msgs::StageCommand normalLoadCommand(double normal_force_kn) {
  auto msg = command(friction_msgs::StageCommand::NORMAL_LOAD);
  msg.normal_force = normal_force_kn * 1e3;
  return msg;
}

std::string replyText(bool call_succeeded, bool accepted, const std::string& reason) {
  if (!call_succeeded) return "no reply: is the simulator running?";
  return accepted ? "accepted" : "refused: " + reason;
}

}  // namespace friction_rviz
