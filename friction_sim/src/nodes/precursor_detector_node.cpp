// The precursor detector node; see friction_sim/ros/precursor_detector.h.
#include <iostream>

#include "friction_sim/ros/precursor_detector.h"
#include "friction_sim/scene/config_error.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "precursor_detector");
  ros::NodeHandle private_nh("~");
  try {
    friction::PrecursorDetector detector{ros::NodeHandle(), private_nh, friction::readDetectorOptions(private_nh)};
    ros::spin();
  } catch (const friction::ConfigError& error) {
    std::cerr << ros::this_node::getName() << ": " << error.what() << std::endl;
    return 2;
  }
  return 0;
}
