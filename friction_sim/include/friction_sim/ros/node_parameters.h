// What the nodes' parameter readers share: the scene overrides the simulator and the precursor
// detector both take, and the reading of a node's parameters with every problem listed.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <utility>
#include <vector>

namespace friction {

/// Splits "key=value key=value" (~overrides) into pairs; appends a problem for each malformed item.
std::vector<std::pair<std::string, std::string>> parseOverrides(const std::string& text,
                                                                std::vector<std::string>& problems);

/// Throws ConfigError titled with this node's parameters if `problems` lists any.
void refuseParameters(const std::vector<std::string>& problems);

/// Reads a node's private parameters into its options struct. A parameter that is unset keeps its
/// default, and each is written back: `rosparam get` then shows every parameter of a running node,
/// defaults included. A number given as text is read as the number (roslaunch passes `rate:=1e4` as the
/// string "1e4"); a value of another type is a problem, named with its value, and keeps the default.
class ParameterReader {
 public:
  explicit ParameterReader(ros::NodeHandle private_nh) : nh_(std::move(private_nh)) {}

  template <class T>
  void read(const std::string& name, T& value) {
    if (nh_.hasParam(name) && !nh_.getParam(name, value) && !readText(name, value)) {
      problems_.push_back(wrongType(name, allowedValues(value)));
    }
    nh_.setParam(name, value);
  }

  /// Throws ConfigError naming the node's parameters if reading found problems or `checks` (the options'
  /// own, from their validation) lists any: every problem at once.
  void refuseIfAny(const std::vector<std::string>& checks) const;

 private:
  bool readText(const std::string& name, double& value) const;
  bool readText(const std::string& name, int& value) const;
  bool readText(const std::string& /*name*/, bool& /*value*/) const { return false; }
  bool readText(const std::string& /*name*/, std::string& /*value*/) const { return false; }
  static const char* allowedValues(double /*value*/) { return "a number"; }
  static const char* allowedValues(int /*value*/) { return "an integer"; }
  static const char* allowedValues(bool /*value*/) { return "true or false"; }
  static const char* allowedValues(const std::string& /*value*/) { return "a string"; }
  std::string wrongType(const std::string& name, const char* allowed) const;

  ros::NodeHandle nh_;
  std::vector<std::string> problems_;
};

}  // namespace friction
