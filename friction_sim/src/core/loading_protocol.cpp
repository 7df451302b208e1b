#include "friction_sim/loading_protocol.h"

#include <cmath>
#include <set>
#include <string>

#include "friction_sim/yaml_fields.h"

namespace friction {

const EnumTable<ProtocolAction>& enumTable(ProtocolAction) {
  static const EnumTable<ProtocolAction> names{{ProtocolAction::NormalLoad, "normal_load"},
                                               {ProtocolAction::Hold, "hold"},
                                               {ProtocolAction::Drive, "drive"},
                                               {ProtocolAction::MoveTo, "move_to"}};
  return names;
}

LoadingProtocol parseProtocol(const std::string& yaml_text, const std::string& source) {
  LoadingProtocol protocol;
  std::vector<std::string> problems;
  const YAML::Node root = loadMapping(yaml_text, "protocol", source);
  YamlFieldReader reader(root, problems);
  // A step whose action was refused has no rules to check its other keys by: they would blame fields
  // the user never wrote.
  std::vector<bool> action_refused;
  std::set<std::string> missing;  // fields not given: their defaults' values are not refused again below
  reader.list("steps", protocol.steps, [&](ProtocolStep& step) {
    const std::string where = "steps[" + std::to_string(action_refused.size()) + "].";
    auto require = [&](const char* key, const std::string& what) {
      if (!reader.require(key, what)) missing.insert(where + key);
    };
    const std::size_t problems_before = problems.size();
    reader.field("action", step.action);
    action_refused.push_back(problems.size() > problems_before);
    // No default stands in for what a step acts with: a move_to without its target drove the stage
    // back to 0 and unloaded the slider (found by a new-user walkthrough).
    if (!action_refused.back()) {
      if (step.action == ProtocolAction::NormalLoad) require("normal_force", "the F_Z to reach, N");
      if (step.action == ProtocolAction::Drive || step.action == ProtocolAction::MoveTo) {
        require("speed", "the stage's speed, m/s");
      }
      if (step.action == ProtocolAction::MoveTo) require("target", "the stage position to move to, m");
    }
    reader.field("normal_force", step.normal_force);
    reader.field("ramp_time", step.ramp_time);
    reader.field("speed", step.speed);
    reader.field("target", step.target);
    reader.field("duration", step.duration);
  });
  reader.section("end", [&] {
    reader.field("global_events", protocol.end.global_events);
    reader.field("stage_travel", protocol.end.stage_travel);
    reader.field("time", protocol.end.time);
  });
  reader.field("ramp_commands", protocol.ramp_commands);
  reader.rejectUnknownKeys();

  auto problem = [&](const std::string& field, double value, const std::string& allowed) {
    if (!missing.count(field)) requireSetting(false, field, value, allowed, problems);
  };
  for (std::size_t i = 0; i < protocol.steps.size(); ++i) {
    const ProtocolStep& step = protocol.steps[i];
    if (i < action_refused.size() && action_refused[i]) continue;
    const std::string where = "steps[" + std::to_string(i) + "]";
    if (step.action == ProtocolAction::NormalLoad) {
      if (!(step.normal_force > 0.0) || !std::isfinite(step.normal_force)) problem(where + ".normal_force", step.normal_force, "a finite F_Z > 0 N");
      if (!(step.ramp_time >= 0.0) || !std::isfinite(step.ramp_time)) problem(where + ".ramp_time", step.ramp_time, "a finite time >= 0 s");
    } else {
      if (!(step.duration > 0.0)) problem(where + ".duration", step.duration, "a duration > 0 s (.inf allowed)");
      if (!std::isfinite(step.speed)) problem(where + ".speed", step.speed, "a finite speed in m/s");
      if (step.action == ProtocolAction::MoveTo && !(step.speed > 0.0)) problem(where + ".speed", step.speed, "a travel speed > 0 m/s");
      if (std::isinf(step.duration) && i + 1 < protocol.steps.size()) {
        problem(where + ".duration", step.duration, "a finite duration: later steps would never run");
      }
    }
  }
  if (protocol.end.global_events < 0) problem("end.global_events", protocol.end.global_events, "a count >= 0");
  if (!(protocol.end.stage_travel > 0.0)) problem("end.stage_travel", protocol.end.stage_travel, "a travel > 0 m");
  if (!(protocol.end.time > 0.0)) problem("end.time", protocol.end.time, "a time > 0 s");
  if (protocol.ramp_commands < 1) problem("ramp_commands", protocol.ramp_commands, "an integer >= 1");
  if (protocol.end.global_events == 0 && std::isinf(protocol.end.stage_travel) && std::isinf(protocol.end.time)) {
    problems.push_back("end: no condition, so the run would never end (a recording one would fill the disk); give "
                       "global_events, stage_travel or time");
  }
  if (!problems.empty()) throw ConfigError("protocol", problems);
  return protocol;
}

LoadingProtocol loadProtocol(const std::string& path) {
  std::vector<std::string> problems;
  const std::string text = readTextFile(path, problems);
  if (!problems.empty()) throw ConfigError("protocol", problems);
  return parseProtocol(text, path);
}

std::vector<TimedCommand> scheduleProtocol(const LoadingProtocol& protocol, double start_time,
                                           double start_normal_force) {
  std::vector<TimedCommand> schedule;
  double time = start_time;
  double normal_force = start_normal_force;
  // The protocol, not the scene's stage program, drives the stage from its start: one that begins by
  // changing F_Z holds the stage until its first stage step (the scene's program had driven it meanwhile).
  if (!protocol.steps.empty() && protocol.steps.front().action == ProtocolAction::NormalLoad) {
    TimedCommand hold;
    hold.time = start_time;
    hold.stage = {StageMode::Hold, 0.0, 0.0};
    schedule.push_back(hold);
  }
  for (const ProtocolStep& step : protocol.steps) {
    if (step.action == ProtocolAction::NormalLoad) {
      const int commands = step.ramp_time > 0.0 ? protocol.ramp_commands : 1;
      for (int k = 1; k <= commands; ++k) {
        TimedCommand command;
        command.kind = TimedCommand::Kind::NormalLoad;
        command.time = time + step.ramp_time * (k - 1) / commands;
        command.normal_force = normal_force + (step.normal_force - normal_force) * k / commands;
        schedule.push_back(command);
      }
      normal_force = step.normal_force;
      time += step.ramp_time;
      continue;
    }
    TimedCommand command;
    command.time = time;
    switch (step.action) {
      case ProtocolAction::Hold:
        command.stage = {StageMode::Hold, 0.0, 0.0};
        break;
      case ProtocolAction::Drive:
        command.stage = {StageMode::Velocity, step.speed, 0.0};
        break;
      default:
        command.stage = {StageMode::Position, step.speed, step.target};
        break;
    }
    schedule.push_back(command);
    if (std::isinf(step.duration)) break;
    time += step.duration;
  }
  return schedule;
}

bool protocolEnded(const ProtocolEnd& end, int global_events, double stage_travel, double elapsed_time) {
  return (end.global_events > 0 && global_events >= end.global_events) || stage_travel >= end.stage_travel ||
         elapsed_time >= end.time;
}

}  // namespace friction
