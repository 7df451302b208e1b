#include "friction_sim/ros/conversions.h"

#include <cmath>

namespace friction {

ros::Time toStamp(double sim_time) { return ros::Time(sim_time); }

namespace {
std_msgs::Header header(double time, const std::string& frame_id) {
  std_msgs::Header out;
  out.stamp = toStamp(time);
  out.frame_id = frame_id;
  return out;
}
}  // namespace

geometry_msgs::WrenchStamped toMsg(const LoadCellReading& reading, const std::string& frame_id) {
  geometry_msgs::WrenchStamped msg;
  msg.header = header(reading.time, frame_id);
  msg.wrench.force.x = reading.shear_force;
  msg.wrench.force.z = -reading.normal_force;
  return msg;
}

LoadCellReading fromMsg(const geometry_msgs::WrenchStamped& msg) {
  LoadCellReading reading;
  reading.time = msg.header.stamp.toSec();
  reading.shear_force = msg.wrench.force.x;
  // F_Z presses down: force.z is -F_Z. Its magnitude is read, so that bags of the rig's first sign
  // convention (+F_Z in force.z) read alike.
  reading.normal_force = std::abs(msg.wrench.force.z);
  return reading;
}

friction_msgs::InterfaceState toMsg(const InterfaceFrame& frame, std::uint32_t frame_index,
                                    const std::string& frame_id) {
  friction_msgs::InterfaceState msg;
  msg.header = header(frame.time, frame_id);
  msg.frame_index = frame_index;
  msg.position = frame.position;
  msg.state = frame.state;
  msg.slip_velocity = frame.slip_velocity;
  msg.slip = frame.slip;
  msg.normal_force = frame.normal_force;
  msg.friction_force = frame.friction_force;
  msg.normal_stress = frame.normal_stress;
  msg.shear_stress = frame.shear_stress;
  msg.static_coefficient = frame.static_coefficient;
  return msg;
}

InterfaceFrame fromMsg(const friction_msgs::InterfaceState& msg) {
  InterfaceFrame frame;
  frame.time = msg.header.stamp.toSec();
  frame.position = msg.position;
  frame.state = msg.state;
  frame.slip_velocity = msg.slip_velocity;
  frame.slip = msg.slip;
  frame.normal_force = msg.normal_force;
  frame.friction_force = msg.friction_force;
  frame.normal_stress = msg.normal_stress;
  frame.shear_stress = msg.shear_stress;
  frame.static_coefficient = msg.static_coefficient;
  return frame;
}

friction_msgs::StrainGaugeProfile toMsg(const GaugeProfile& profile, const std::string& frame_id) {
  friction_msgs::StrainGaugeProfile msg;
  msg.header = header(profile.time, frame_id);
  msg.height = profile.height;
  msg.position = profile.position;
  msg.sigma_xx.assign(profile.stress.sigma_xx.begin(), profile.stress.sigma_xx.end());
  msg.sigma_zz.assign(profile.stress.sigma_zz.begin(), profile.stress.sigma_zz.end());
  msg.tau_xz.assign(profile.stress.tau_xz.begin(), profile.stress.tau_xz.end());
  return msg;
}

friction_msgs::SlipEvent toMsg(const SlipEvent& event, const std::vector<double>& positions, double slider_length,
                               const WaveSpeeds& speeds, const std::string& frame_id) {
  friction_msgs::SlipEvent msg;
  msg.header = header(event.end_time, frame_id);
  msg.index = event.index;
  msg.onset_time = event.onset_time;
  msg.end_time = event.end_time;
  msg.onset_shear_force = event.onset_shear_force;
  msg.onset_normal_force = event.onset_normal_force;
  msg.end_shear_force = event.end_shear_force;
  msg.peak_shear_force = event.peak_shear_force;
  msg.mean_shear_force = event.mean_shear_force;
  msg.mean_normal_force = event.mean_normal_force;
  msg.nucleation_position = event.nucleation_position;
  msg.slip_min_x = event.slip_min_x;
  msg.slip_max_x = event.slip_max_x;
  msg.rupture_length = event.rupture_length;
  msg.slider_length = slider_length;
  msg.global_event = event.global;
  msg.kind = static_cast<std::uint8_t>(event.kind);
  msg.unfinished = event.unfinished;
  msg.mean_slip = event.meanSlip();
  msg.position = positions;
  msg.node_slip = event.node_slip;
  msg.first_unstick_time = event.first_unstick_time;
  msg.front_speed = event.front_speed;
  msg.median_front_speed = event.median_front_speed;
  msg.front_fits_left_out = static_cast<std::uint32_t>(event.front_fits_left_out);
  msg.rayleigh_speed = speeds.rayleigh;
  msg.shear_wave_speed = speeds.shear;
  msg.longitudinal_wave_speed = speeds.longitudinal;
  return msg;
}

SlipEvent fromMsg(const friction_msgs::SlipEvent& msg) {
  SlipEvent event;
  event.index = static_cast<int>(msg.index);
  event.onset_time = msg.onset_time;
  event.end_time = msg.end_time;
  event.onset_shear_force = msg.onset_shear_force;
  event.onset_normal_force = msg.onset_normal_force;
  event.end_shear_force = msg.end_shear_force;
  event.peak_shear_force = msg.peak_shear_force;
  event.mean_shear_force = msg.mean_shear_force;
  event.mean_normal_force = msg.mean_normal_force;
  event.nucleation_position = msg.nucleation_position;
  event.slip_min_x = msg.slip_min_x;
  event.slip_max_x = msg.slip_max_x;
  event.rupture_length = msg.rupture_length;
  event.global = msg.global_event;
  event.kind = static_cast<SlipEventKind>(msg.kind);
  event.unfinished = msg.unfinished;
  event.node_slip = msg.node_slip;
  event.first_unstick_time = msg.first_unstick_time;
  event.front_speed = msg.front_speed;
  event.median_front_speed = msg.median_front_speed;
  event.front_fits_left_out = static_cast<int>(msg.front_fits_left_out);
  return event;
}

friction_msgs::PrecursorPoint toPointMsg(const SlipEvent& event, double slider_length, const std::string& frame_id) {
  friction_msgs::PrecursorPoint msg;
  msg.header = header(event.onset_time, frame_id);
  msg.event_index = event.index;
  msg.shear_ratio = event.onset_shear_force / event.onset_normal_force;
  msg.length_ratio = event.rupture_length / slider_length;
  msg.global_event = event.global;
  msg.back_slip = event.backSlip();
  return msg;
}

friction_msgs::LatticeSnapshot toMsg(const LatticeSnapshot& snapshot, const std::string& frame_id) {
  friction_msgs::LatticeSnapshot msg;
  msg.header = header(snapshot.time, frame_id);
  msg.nodes_x = snapshot.nodes_x;
  msg.nodes_z = snapshot.nodes_z;
  msg.spacing = snapshot.spacing;
  msg.x.assign(snapshot.x.begin(), snapshot.x.end());
  msg.z.assign(snapshot.z.begin(), snapshot.z.end());
  msg.speed.assign(snapshot.speed.begin(), snapshot.speed.end());
  msg.sigma_xx.assign(snapshot.stress.sigma_xx.begin(), snapshot.stress.sigma_xx.end());
  msg.sigma_zz.assign(snapshot.stress.sigma_zz.begin(), snapshot.stress.sigma_zz.end());
  msg.tau_xz.assign(snapshot.stress.tau_xz.begin(), snapshot.stress.tau_xz.end());
  msg.interface_state = snapshot.interface_state;
  msg.stage_position = snapshot.stage_position;
  msg.pusher_height = snapshot.pusher_height;
  msg.normal_force = snapshot.normal_force;
  return msg;
}

TimedCommand fromMsg(const friction_msgs::StageCommand& msg) {
  TimedCommand command;
  command.time = msg.header.stamp.toSec();
  switch (msg.mode) {
    case friction_msgs::StageCommand::NORMAL_LOAD:
      command.kind = TimedCommand::Kind::NormalLoad;
      command.normal_force = msg.normal_force;
      break;
    case friction_msgs::StageCommand::VELOCITY:
      command.stage = {StageMode::Velocity, msg.speed, msg.target};
      break;
    case friction_msgs::StageCommand::POSITION:
      command.stage = {StageMode::Position, msg.speed, msg.target};
      break;
    default:  // HOLD; an unknown mode is refused before (checkCommand)
      // A hold has no speed or target: the message's fields are left over from the sender, not asked for.
      command.stage = {StageMode::Hold, 0.0, 0.0};
      break;
  }
  return command;
}

friction_msgs::StageCommand toMsg(const TimedCommand& command) {
  friction_msgs::StageCommand msg;
  msg.header.stamp = toStamp(command.time);
  if (command.kind == TimedCommand::Kind::NormalLoad) {
    msg.mode = friction_msgs::StageCommand::NORMAL_LOAD;
    msg.normal_force = command.normal_force;
    return msg;
  }
  msg.speed = command.stage.speed;
  msg.target = command.stage.target;
  msg.mode = toMsgMode(command.stage.mode);
  return msg;
}

std::uint8_t toMsgMode(StageMode mode) {
  using Command = friction_msgs::StageCommand;
  using State = friction_msgs::StageState;
  static_assert(int{State::VELOCITY} == int{Command::VELOCITY} && int{State::HOLD} == int{Command::HOLD} &&
                    int{State::POSITION} == int{Command::POSITION},
                "StageState and StageCommand number the stage's modes alike");
  switch (mode) {
    case StageMode::Velocity:
      return friction_msgs::StageCommand::VELOCITY;
    case StageMode::Position:
      return friction_msgs::StageCommand::POSITION;
    case StageMode::Hold:
      break;
  }
  return friction_msgs::StageCommand::HOLD;
}

}  // namespace friction
