// What the nodes' parameter readers share: the scene overrides the simulator and the precursor
// detector both take, and the refusal of a node's parameters with every problem listed.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <utility>
#include <vector>

namespace friction {

/// Splits "key=value key=value" (~overrides) into pairs; appends a problem for each malformed item.
std::vector<std::pair<std::string, std::string>> parseOverrides(const std::string& text,
                                                                std::vector<std::string>& problems);

/// Reads the private parameter `name` into `value`, which keeps its default if the parameter is unset, and
/// writes the value back: `rosparam get` then shows every parameter of a running node, defaults included.
template <class T>
void readParameter(const ros::NodeHandle& private_nh, const std::string& name, T& value) {
  private_nh.param(name, value, value);
  private_nh.setParam(name, value);
}

/// Throws ConfigError naming the node's parameters if `problems` lists any (the end of each read*Options).
void refuseParameters(const ros::NodeHandle& private_nh, const std::vector<std::string>& problems);

}  // namespace friction
