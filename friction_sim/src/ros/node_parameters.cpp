#include "friction_sim/ros/node_parameters.h"

#include <cerrno>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>

#include <ros/this_node.h>

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

namespace {

/// The whole of `text` as a number (surrounding blanks allowed), or nothing.
template <class Number>
std::optional<Number> parseWhole(const std::string& text, Number (*parse)(const char*, char**)) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const Number parsed = parse(begin, &end);
  if (end == begin || errno == ERANGE) return std::nullopt;
  while (*end == ' ' || *end == '\t') ++end;
  if (*end != '\0') return std::nullopt;
  return parsed;
}

double parseDouble(const char* text, char** end) { return std::strtod(text, end); }
long parseLong(const char* text, char** end) { return std::strtol(text, end, 10); }

}  // namespace

bool ParameterReader::readText(const std::string& name, double& value) const {
  std::string text;
  if (!nh_.getParam(name, text)) return false;
  const auto parsed = parseWhole<double>(text, parseDouble);
  if (parsed) value = *parsed;
  return parsed.has_value();
}

bool ParameterReader::readText(const std::string& name, int& value) const {
  std::string text;
  if (!nh_.getParam(name, text)) return false;
  const auto parsed = parseWhole<long>(text, parseLong);
  if (!parsed || *parsed < std::numeric_limits<int>::min() || *parsed > std::numeric_limits<int>::max()) return false;
  value = static_cast<int>(*parsed);
  return true;
}

std::string ParameterReader::wrongType(const std::string& name, const char* allowed) const {
  XmlRpc::XmlRpcValue given;
  nh_.getParam(name, given);
  std::ostringstream problem;
  problem << "~" << name << ": value ";
  if (given.getType() == XmlRpc::XmlRpcValue::TypeString) {
    problem << "'" << static_cast<std::string&>(given) << "'";
  } else {
    given.write(problem);
  }
  problem << " is not allowed; allowed: " << allowed;
  return problem.str();
}

void ParameterReader::refuseIfAny(const std::vector<std::string>& checks) const {
  std::vector<std::string> problems = problems_;
  problems.insert(problems.end(), checks.begin(), checks.end());
  refuseParameters(problems);
}

void refuseParameters(const std::vector<std::string>& problems) {
  if (!problems.empty()) throw ConfigError("parameters of " + ros::this_node::getName(), problems);
}

}  // namespace friction
