// Reading YAML mappings field by field with every problem collected: unknown keys (typos must not
// fall back to defaults), wrong types and unknown enum names, each reported with its dotted path.
// Enums are read through an `enumTable(E)` overload, found by argument-dependent lookup, that lists
// each value with its name.
#pragma once

#include <yaml-cpp/yaml.h>

#include "friction_sim/scene/config_error.h"

#include <functional>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace friction {

/// Parses YAML text whose top level must be a mapping; throws ConfigError about `what` otherwise. A
/// syntax error names `source`, the file the text came from ("" for text given directly).
YAML::Node loadMapping(const std::string& text, const std::string& what, const std::string& source = "");

/// Reads a whole text file; adds a problem if it cannot be read.
std::string readTextFile(const std::string& path, std::vector<std::string>& problems);

template <class E>
using EnumTable = std::vector<std::pair<E, const char*>>;

template <class E>
std::string allowedNames(const EnumTable<E>& table) {
  std::string out;
  for (const auto& entry : table) out += (out.empty() ? "" : " | ") + std::string(entry.second);
  return out;
}

class YamlFieldReader {
 public:
  YamlFieldReader(const YAML::Node& root, std::vector<std::string>& problems) : node_(root), problems_(problems) {}

  template <class T>
  void field(const char* key, T& value) {
    used_.insert(key);
    const YAML::Node child = node_[key];
    if (!child) return;
    read(child, path(key), value);
  }

  /// Reports `key` if the current mapping lacks it (`what` says what it is for); false then.
  bool require(const char* key, const std::string& what) {
    if (node_[key]) return true;
    problems_.push_back(path(key) + ": not given; needed: " + what);
    return false;
  }

  void section(const char* key, const std::function<void()>& body) {
    used_.insert(key);
    const YAML::Node child = node_[key];
    if (!child) return;
    if (!child.IsMap()) {
      problems_.push_back(path(key) + ": expected a mapping of fields");
      return;
    }
    enter(child, path(key), body);
  }

  template <class T, class Body>
  void list(const char* key, std::vector<T>& items, Body&& body) {
    used_.insert(key);
    const YAML::Node child = node_[key];
    if (!child) return;
    if (!child.IsSequence() || child.size() == 0) {
      problems_.push_back(path(key) + ": expected a non-empty list");
      return;
    }
    items.assign(child.size(), T{});
    for (std::size_t i = 0; i < child.size(); ++i) {
      const std::string item_path = path(key) + "[" + std::to_string(i) + "]";
      if (!child[i].IsMap()) {
        problems_.push_back(item_path + ": expected a mapping of fields");
        continue;
      }
      enter(child[i], item_path, [&] { body(items[i]); });
    }
  }

  /// Reports every key of the current mapping that no field claimed, and every key given twice (YAML
  /// forbids it; yaml-cpp keeps both and the first would win without a word).
  void rejectUnknownKeys() {
    std::set<std::string> seen;
    for (const auto& entry : node_) {
      const std::string key = entry.first.as<std::string>();
      if (!seen.insert(key).second) problems_.push_back(path(key) + ": given more than once; give it once");
      if (!used_.count(key)) {
        std::string allowed;
        for (const auto& name : used_) allowed += (allowed.empty() ? "" : ", ") + name;
        problems_.push_back(path(key) + ": unknown key; allowed keys here: " + allowed);
      }
    }
  }

 private:
  void enter(const YAML::Node& child, const std::string& child_path, const std::function<void()>& body) {
    YAML::Node saved_node = node_;
    std::string saved_prefix = prefix_;
    std::set<std::string> saved_used;
    saved_used.swap(used_);
    node_.reset(child);
    prefix_ = child_path + ".";
    body();
    rejectUnknownKeys();
    node_.reset(saved_node);
    prefix_ = saved_prefix;
    used_.swap(saved_used);
  }

  std::string path(const std::string& key) const { return prefix_ + key; }

  void read(const YAML::Node& node, const std::string& where, double& value) {
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      problems_.push_back(where + ": value '" + YAML::Dump(node) + "' is not a number");
    }
  }
  void read(const YAML::Node& node, const std::string& where, int& value) {
    try {
      value = node.as<int>();
    } catch (const YAML::Exception&) {
      problems_.push_back(where + ": value '" + YAML::Dump(node) + "' is not an integer");
    }
  }
  void read(const YAML::Node& node, const std::string& where, bool& value) {
    try {
      value = node.as<bool>();
    } catch (const YAML::Exception&) {
      problems_.push_back(where + ": value '" + YAML::Dump(node) + "' is not allowed; allowed: true | false");
    }
  }
  void read(const YAML::Node& node, const std::string& where, std::string& value) {
    if (!node.IsScalar()) {
      problems_.push_back(where + ": expected a string");
      return;
    }
    value = node.as<std::string>();
  }
  void read(const YAML::Node& node, const std::string& where, std::vector<double>& value) {
    if (!node.IsSequence()) {
      problems_.push_back(where + ": expected a list of numbers");
      return;
    }
    value.clear();
    for (std::size_t i = 0; i < node.size(); ++i) {
      double item = 0.0;
      read(node[i], where + "[" + std::to_string(i) + "]", item);
      value.push_back(item);
    }
  }
  template <class E, class = std::enable_if_t<std::is_enum<E>::value>>
  void read(const YAML::Node& node, const std::string& where, E& value) {
    const std::string text = node.IsScalar() ? node.as<std::string>() : YAML::Dump(node);
    for (const auto& entry : enumTable(E{})) {
      if (text == entry.second) {
        value = entry.first;
        return;
      }
    }
    problems_.push_back(where + ": value '" + text + "' is not allowed; allowed: " + allowedNames(enumTable(E{})));
  }

  YAML::Node node_;
  std::string prefix_;
  std::set<std::string> used_;
  std::vector<std::string>& problems_;
};

}  // namespace friction
