#include "friction_sim/ros/node_parameters.h"

#include <sstream>

#include "friction_sim/scene/config_error.h"

namespace friction {

std::vector<std::pair<std::string, std::string>> parseOverrides(const std::string& text,
                                                                std::vector<std::string>& problems) {
  std::vector<std::pair<std::string, std::string>> overrides;
  std::istringstream stream(text);
  for (std::string item; stream >> item;) {
    const auto equals = item.find('=');
    if (equals == std::string::npos || equals == 0) {
      problems.push_back("~overrides: item '" + item + "' is not allowed; allowed: key=value, e.g. pusher.height=0.01");
      continue;
    }
    overrides.emplace_back(item.substr(0, equals), item.substr(equals + 1));
  }
  return overrides;
}

void refuseParameters(const ros::NodeHandle& private_nh, const std::vector<std::string>& problems) {
  if (!problems.empty()) throw ConfigError("parameters of " + private_nh.getNamespace(), problems);
}

}  // namespace friction
