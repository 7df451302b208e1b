// Core structs to and from the rig's ROS messages. Needs the message headers but no master, so the
// conversions are unit-tested on their own.
#pragma once

#include <friction_msgs/InterfaceState.h>
#include <friction_msgs/LatticeSnapshot.h>
#include <friction_msgs/PrecursorPoint.h>
#include <friction_msgs/SlipEvent.h>
#include <friction_msgs/StageCommand.h>
#include <friction_msgs/StageState.h>
#include <friction_msgs/StrainGaugeProfile.h>
#include <geometry_msgs/WrenchStamped.h>
#include <ros/time.h>

#include <string>

#include "friction_sim/instruments/instruments.h"
#include "friction_sim/instruments/slip_events.h"
#include "friction_sim/scene/loading_protocol.h"
#include "friction_sim/stage/stage.h"

namespace friction {

/// Simulated time (s) as a ROS stamp.
ros::Time toStamp(double sim_time);

/// Load cells as the force that the loading stage and the normal-load frame apply to the slider, in the
/// slider frame (REP 103, z up): force.x = F_X (a push along +x is +), force.z = −F_Z (pressing down).
geometry_msgs::WrenchStamped toMsg(const LoadCellReading& reading, const std::string& frame_id);
LoadCellReading fromMsg(const geometry_msgs::WrenchStamped& msg);

friction_msgs::InterfaceState toMsg(const InterfaceFrame& frame, std::uint32_t frame_index,
                                    const std::string& frame_id);
InterfaceFrame fromMsg(const friction_msgs::InterfaceState& msg);

friction_msgs::StrainGaugeProfile toMsg(const GaugeProfile& profile, const std::string& frame_id);

/// `speeds`: the model's, carried by every event so that v_c/c_R can be formed downstream.
friction_msgs::SlipEvent toMsg(const SlipEvent& event, const std::vector<double>& positions, double slider_length,
                               const WaveSpeeds& speeds, const std::string& frame_id);
SlipEvent fromMsg(const friction_msgs::SlipEvent& msg);

friction_msgs::PrecursorPoint toPointMsg(const SlipEvent& event, double slider_length, const std::string& frame_id);

friction_msgs::LatticeSnapshot toMsg(const LatticeSnapshot& snapshot, const std::string& frame_id);

/// Commands: the message's mode picks a stage command or a normal-load change; stamp = when.
TimedCommand fromMsg(const friction_msgs::StageCommand& msg);
friction_msgs::StageCommand toMsg(const TimedCommand& command);
/// The stage's mode as StageCommand and StageState number it.
std::uint8_t toMsgMode(StageMode mode);

}  // namespace friction
