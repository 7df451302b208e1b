// What the rig panel's buttons send (drawing-free, unit-tested): stage commands built from the
// panel's fields, in the panel's units (mm, mm/s, kN), converted to the message's SI units. The
// simulator is the one that accepts or refuses; the panel shows its verdict.
#pragma once

#include <friction_msgs/StageCommand.h>

#include <string>

namespace friction_rviz {

friction_msgs::StageCommand driveCommand(double speed_mm_per_s);
friction_msgs::StageCommand holdCommand();
friction_msgs::StageCommand moveCommand(double target_mm, double speed_mm_per_s);
friction_msgs::StageCommand normalLoadCommand(double normal_force_kn);

/// The line the panel shows for a reply.
std::string replyText(bool call_succeeded, bool accepted, const std::string& reason);

}  // namespace friction_rviz
