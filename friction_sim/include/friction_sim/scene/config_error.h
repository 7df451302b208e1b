// What refusing a setting looks like everywhere in the rig: a configuration (scene, protocol, a node's
// parameters) refused with every problem listed, each naming the field, the value and what is allowed.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace friction {

/// A configuration file (scene, protocol) refused: `problems()` holds one message per problem, each
/// naming the field, the value and what is allowed.
class ConfigError : public std::runtime_error {
 public:
  /// `notes`: what the problems kept from being checked; listed after them, not counted among them.
  ConfigError(const std::string& what_was_refused, std::vector<std::string> problems,
              std::vector<std::string> notes = {});
  const std::vector<std::string>& problems() const { return problems_; }
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  std::vector<std::string> problems_;
  std::vector<std::string> notes_;
};

/// A refused value as refusals write it: ten digits, and NaN as "nan" whatever its sign bit, which the
/// sender's arithmetic decides ("-nan" reads as a value).
std::string refusedValueText(double value);

/// Appends "field: value V is not allowed; allowed: A" to `problems` unless `ok`: the one form of the
/// refusals of a scene's, a protocol's and a node's settings (a command's refusal says what it asked
/// for in its own words). V as refusedValueText writes it.
void requireSetting(bool ok, const std::string& field, double value, const std::string& allowed,
                    std::vector<std::string>& problems);

}  // namespace friction
