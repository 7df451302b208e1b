// The rig simulator node; see friction_sim/ros/rig_simulator.h for its parameters, topics and services.
#include <csignal>
#include <iostream>

#include "friction_sim/ros/rig_simulator.h"
#include "friction_sim/scene/config_error.h"
#include "process_memory.h"

int main(int argc, char** argv) {
  // Its start-up builds and factors the slider as friction_run's does, with the same many large arrays.
  friction::reuseFreedMemoryOnHugePages();
  ros::init(argc, argv, "rig_simulator", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, [](int) { friction::g_stop_requested = true; });
  std::signal(SIGTERM, [](int) { friction::g_stop_requested = true; });
  // Past a file size limit (ulimit -f) the bag's write then fails, and the node ends the run saying so,
  // rather than being killed with the bag unclosed.
  std::signal(SIGXFSZ, SIG_IGN);
  try {
    friction::RigSimulator simulator{ros::NodeHandle(), friction::readSimulatorOptions(ros::NodeHandle("~"))};
    simulator.run();
    if (simulator.bagFailed()) return 3;
    if (simulator.aborted()) return 4;
    if (simulator.subscribersMissing()) return 5;
  } catch (const friction::ConfigError& error) {
    std::cerr << ros::this_node::getName() << ": " << error.what() << std::endl;
    return 2;
  }
  return 0;
}
