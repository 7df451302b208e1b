// The loading-stage controller node; see friction_sim/ros/stage_controller.h.
#include <iostream>

#include "friction_sim/ros/stage_controller.h"
#include "friction_sim/yaml_fields.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "stage_controller");
  std::string protocol_path;
  ros::NodeHandle("~").param<std::string>("protocol", protocol_path, "");
  try {
    friction::StageController controller{ros::NodeHandle(), friction::loadProtocol(protocol_path)};
    ros::spin();
  } catch (const friction::ConfigError& error) {
    std::cerr << error.what() << std::endl;
    return 2;
  }
  return 0;
}
