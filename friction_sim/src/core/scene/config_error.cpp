#include "friction_sim/scene/config_error.h"

#include <cmath>
#include <sstream>
#include <utility>

namespace friction {

ConfigError::ConfigError(const std::string& what_was_refused, std::vector<std::string> problems,
                         std::vector<std::string> notes)
    : std::runtime_error([&] {
        std::string text = what_was_refused + " refused (" + std::to_string(problems.size()) + " problem" +
                           (problems.size() == 1 ? "" : "s") + "):";
        for (const auto& problem : problems) text += "\n  - " + problem;
        for (const auto& note : notes) text += "\n  note: " + note;
        return text;
      }()),
      problems_(std::move(problems)),
      notes_(std::move(notes)) {}

std::string refusedValueText(double value) {
  if (std::isnan(value)) return "nan";
  std::ostringstream text;
  text.precision(10);
  text << value;
  return text.str();
}

void requireSetting(bool ok, const std::string& field, double value, const std::string& allowed,
                    std::vector<std::string>& problems) {
  if (ok) return;
  problems.push_back(field + ": value " + refusedValueText(value) + " is not allowed; allowed: " + allowed);
}

}  // namespace friction
