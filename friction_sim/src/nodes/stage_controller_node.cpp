// The loading-stage controller node; see friction_sim/ros/stage_controller.h.
#include <iostream>

#include "friction_sim/ros/stage_controller.h"
#include "friction_sim/yaml_fields.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "stage_controller");
  std::string protocol_path;
  double start_delay = 1.0;
  ros::NodeHandle private_nh("~");
  private_nh.param<std::string>("protocol", protocol_path, "");
  private_nh.param("start_delay", start_delay, start_delay);
  try {
    if (!(start_delay >= 0.0)) {
      throw friction::ConfigError("parameters of " + private_nh.getNamespace(),
                                  {"~start_delay: value " + std::to_string(start_delay) + " is not allowed; allowed: >= 0 s"});
    }
    friction::StageController controller{ros::NodeHandle(), friction::loadProtocol(protocol_path), start_delay};
    ros::spin();
  } catch (const friction::ConfigError& error) {
    std::cerr << error.what() << std::endl;
    // A simulator started paused waits for this node's protocol: end its run rather than leave it waiting.
    ros::NodeHandle nh;
    friction::stopSimulator(nh, ros::WallDuration(10.0));
    return 2;
  }
  return 0;
}
