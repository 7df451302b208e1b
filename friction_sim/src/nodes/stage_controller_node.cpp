// The loading-stage controller node; see friction_sim/ros/stage_controller.h.
#include <iostream>

#include "friction_sim/ros/stage_controller.h"
#include "friction_sim/scene/config_error.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "stage_controller");
  ros::NodeHandle private_nh("~");
  try {
    const friction::ControllerOptions options = friction::readControllerOptions(private_nh);
    friction::StageController controller{ros::NodeHandle(), friction::loadProtocol(options.protocol_path),
                                         options.start_delay};
    ros::spin();
    if (controller.failed()) return 2;
  } catch (const friction::ConfigError& error) {
    std::cerr << ros::this_node::getName() << ": " << error.what() << std::endl;
    // A simulator started paused waits for this node's protocol: end its run, as failed, rather than
    // leave it waiting.
    ros::NodeHandle nh;
    friction::endSimulatorRun(nh, "abort", ros::WallDuration(60.0));
    return 2;
  }
  return 0;
}
