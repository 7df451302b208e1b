#include "friction_sim/scene/loading_protocol.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <set>
#include <sstream>
#include <string>

#include "scene/yaml_fields.h"

namespace friction {

const EnumTable<ProtocolAction>& enumTable(ProtocolAction) {
  static const EnumTable<ProtocolAction> names{{ProtocolAction::NormalLoad, "normal_load"},
                                               {ProtocolAction::Hold, "hold"},
                                               {ProtocolAction::Drive, "drive"},
                                               {ProtocolAction::MoveTo, "move_to"}};
  return names;
}

namespace {

/// What reading a protocol's YAML leaves for the checks of its values.
struct ProtocolReading {
  /// Per step: its action was refused. Such a step has no rules to check its other keys by: they would
  /// blame fields the user never wrote.
  std::vector<bool> action_refused;
  /// Fields not given: their defaults' values are not refused again.
  std::set<std::string> missing;
};

/// Reads the protocol's fields into `protocol`, with every unknown key, wrong type and missing field in
/// `problems`.
ProtocolReading readProtocolFields(const YAML::Node& root, LoadingProtocol& protocol,
                                   std::vector<std::string>& problems) {
  ProtocolReading reading;
  YamlFieldReader reader(root, problems);
  reader.list("steps", protocol.steps, [&](ProtocolStep& step) {
    const std::string where = "steps[" + std::to_string(reading.action_refused.size()) + "].";
    const std::size_t problems_before = problems.size();
    reader.field("action", step.action);
    reading.action_refused.push_back(problems.size() > problems_before);
    const bool known = !reading.action_refused.back();
    // Only the fields its action acts with: another (a duration on normal_load, a speed on hold) would
    // be read and ignored, while its writer expects it to act. Past a refused action, all of them.
    auto uses = [&](std::initializer_list<ProtocolAction> actions) {
      return !known || std::find(actions.begin(), actions.end(), step.action) != actions.end();
    };
    // No default stands in for what a step acts with: a move_to without its target would drive the
    // stage back to 0 and unload the slider.
    auto required = [&](const char* key, const std::string& what, double& value) {
      if (known && !reader.require(key, what)) reading.missing.insert(where + key);
      reader.field(key, value);
    };
    if (uses({ProtocolAction::NormalLoad})) {
      required("normal_force", "the F_Z to reach, N", step.normal_force);
      reader.field("ramp_time", step.ramp_time);
    }
    if (uses({ProtocolAction::Drive, ProtocolAction::MoveTo})) required("speed", "the stage's speed, m/s", step.speed);
    if (uses({ProtocolAction::MoveTo})) required("target", "the stage position to move to, m", step.target);
    if (uses({ProtocolAction::Hold, ProtocolAction::Drive, ProtocolAction::MoveTo})) {
      reader.field("duration", step.duration);
    }
  });
  reader.section("end", [&] {
    reader.field("global_events", protocol.end.global_events);
    reader.field("stage_travel", protocol.end.stage_travel);
    reader.field("time", protocol.end.time);
  });
  reader.field("ramp_commands", protocol.ramp_commands);
  reader.rejectUnknownKeys();
  return reading;
}

/// Reports a protocol field's value out of its range: (field, value, what is allowed).
using ProtocolProblem = std::function<void(const std::string&, double, const std::string&)>;

/// Reports every value of step `i` of `protocol` out of its range.
void checkProtocolStep(const LoadingProtocol& protocol, std::size_t i, const ProtocolProblem& problem) {
  const ProtocolStep& step = protocol.steps[i];
  const std::string where = "steps[" + std::to_string(i) + "]";
  if (step.action == ProtocolAction::NormalLoad) {
    if (!(step.normal_force > 0.0) || !std::isfinite(step.normal_force))
      problem(where + ".normal_force", step.normal_force, "a finite F_Z > 0 N");
    if (!(step.ramp_time >= 0.0) || !std::isfinite(step.ramp_time))
      problem(where + ".ramp_time", step.ramp_time, "a finite time >= 0 s");
    return;
  }
  if (!(step.duration > 0.0)) problem(where + ".duration", step.duration, "a duration > 0 s (.inf allowed)");
  if (!std::isfinite(step.speed)) problem(where + ".speed", step.speed, "a finite speed in m/s");
  if (step.action == ProtocolAction::MoveTo && !(step.speed > 0.0))
    problem(where + ".speed", step.speed, "a travel speed > 0 m/s");
  if (std::isinf(step.duration) && i + 1 < protocol.steps.size()) {
    problem(where + ".duration", step.duration, "a finite duration: later steps would never run");
  }
}

/// Adds to `problems` every value of the protocol out of its range.
void checkProtocolValues(const LoadingProtocol& protocol, const ProtocolReading& reading,
                         std::vector<std::string>& problems) {
  const ProtocolProblem problem = [&](const std::string& field, double value, const std::string& allowed) {
    if (!reading.missing.count(field)) requireSetting(false, field, value, allowed, problems);
  };
  for (std::size_t i = 0; i < protocol.steps.size(); ++i) {
    if (i < reading.action_refused.size() && reading.action_refused[i]) continue;
    checkProtocolStep(protocol, i, problem);
  }
  if (protocol.end.global_events < 0) problem("end.global_events", protocol.end.global_events, "a count >= 0");
  if (!(protocol.end.stage_travel > 0.0)) problem("end.stage_travel", protocol.end.stage_travel, "a travel > 0 m");
  if (!(protocol.end.time > 0.0)) problem("end.time", protocol.end.time, "a time > 0 s");
  if (protocol.ramp_commands < 1) problem("ramp_commands", protocol.ramp_commands, "an integer >= 1");
  if (!endsTheRun(protocol.end.stopFrom(0.0))) {
    problems.push_back(std::string("end: ") + kNoEndProblem);
  }
}

}  // namespace

LoadingProtocol parseProtocol(const std::string& yaml_text, const std::string& source) {
  LoadingProtocol protocol;
  std::vector<std::string> problems;
  const ProtocolReading reading = readProtocolFields(loadMapping(yaml_text, "protocol", source), protocol, problems);
  checkProtocolValues(protocol, reading, problems);
  if (!problems.empty()) throw ConfigError("protocol", problems);
  return protocol;
}

LoadingProtocol loadProtocol(const std::string& path) {
  std::vector<std::string> problems;
  const std::string text = readTextFile(path, problems);
  if (!problems.empty()) throw ConfigError("protocol", problems);
  return parseProtocol(text, path);
}

TimedCommand stepCommand(const ProtocolStep& step) {
  TimedCommand command;
  switch (step.action) {
    case ProtocolAction::NormalLoad:
      command.kind = TimedCommand::Kind::NormalLoad;
      command.normal_force = step.normal_force;
      break;
    case ProtocolAction::Hold:
      command.stage = {StageMode::Hold, 0.0, 0.0};
      break;
    case ProtocolAction::Drive:
      command.stage = {StageMode::Velocity, step.speed, 0.0};
      break;
    case ProtocolAction::MoveTo:
      command.stage = {StageMode::Position, step.speed, step.target};
      break;
  }
  return command;
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
    TimedCommand command = stepCommand(step);
    command.time = time;
    schedule.push_back(command);
    if (std::isinf(step.duration)) break;
    time += step.duration;
  }
  return schedule;
}

double stampSeconds(double seconds) {
  // ros::Time::fromSec, then toSec: the whole seconds, the rest rounded half away from zero to a
  // nanosecond, carried into the seconds when it rounds up to one.
  double whole = std::floor(seconds);
  double nanoseconds = std::round((seconds - whole) * 1e9);
  if (nanoseconds >= 1e9) {
    whole += 1.0;
    nanoseconds -= 1e9;
  }
  return whole + 1e-9 * nanoseconds;
}

namespace {

/// The command table's columns in order, as rig_report writes them.
constexpr std::array<const char*, 5> kCommandTableColumns{"time_s", "command", "speed_m_s", "target_m",
                                                          "normal_force_N"};

/// The columns' names joined by `separator`.
std::string commandTableColumns(const std::string& separator) {
  std::string joined;
  for (const char* column : kCommandTableColumns) joined += (joined.empty() ? "" : separator) + column;
  return joined;
}

/// A number that fills all of `text` (C syntax, inf and nan included).
bool readNumber(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

/// A time in seconds. Written with at most nine decimals, as rig_report writes a bag's stamps, it is
/// read as whole seconds and nanoseconds and summed as ros::Time::toSec() sums them: the rig compared
/// the command's time with its clock as that double, and a rerun that jumps to the next command must
/// land on the same one to reproduce the run bit for bit (the nearest double to the decimal text can
/// differ from it in the last bit).
bool readStampSeconds(const std::string& text, double& seconds) {
  const auto point = text.find('.');
  const std::string whole = text.substr(0, point);
  const std::string fraction = point == std::string::npos ? "" : text.substr(point + 1);
  const auto digits = [](const std::string& part) { return part.find_first_not_of("0123456789") == std::string::npos; };
  if (whole.empty() || whole.size() > 9 || fraction.size() > 9 || !digits(whole) || !digits(fraction)) {
    return readNumber(text, seconds);
  }
  const double nanoseconds = fraction.empty() ? 0.0 : std::stod(fraction + std::string(9 - fraction.size(), '0'));
  seconds = std::stod(whole) + 1e-9 * nanoseconds;
  return true;
}

/// Reads a command table row's time (cell 0) into `command`: a finite time >= 0 s, not before the row
/// `before` (the last row read whose time was good, or null). Reports a problem and returns false if it
/// cannot be read.
bool readCommandTime(const std::string& cell, const TimedCommand* before, TimedCommand& command,
                     const std::function<void(const std::string&)>& problem) {
  if (!readStampSeconds(cell, command.time) || !std::isfinite(command.time) || command.time < 0.0) {
    problem("time_s '" + cell + "' is not allowed; allowed: a finite time >= 0 s");
    return false;
  }
  if (before && command.time < before->time) {
    problem("time_s " + cell + " is earlier than the row before; allowed: rows in time order");
  }
  return true;
}

/// Reads a command table row's command and the fields it takes (cells 1 to 4) into `command`, reporting
/// each problem; false if the command is unknown.
bool readCommandFields(const std::vector<std::string>& cells, TimedCommand& command,
                       const std::function<void(const std::string&)>& problem) {
  // The fields each command takes, by column from the third (speed, target, normal_force).
  std::array<bool, 3> takes{};
  const std::string& name = cells[1];
  if (name == "velocity") {
    command.stage = {StageMode::Velocity, 0.0, 0.0};
    takes = {true, false, false};
  } else if (name == "hold") {
    command.stage = {StageMode::Hold, 0.0, 0.0};
  } else if (name == "position") {
    command.stage = {StageMode::Position, 0.0, 0.0};
    takes = {true, true, false};
  } else if (name == "normal_load") {
    command.kind = TimedCommand::Kind::NormalLoad;
    takes = {false, false, true};
  } else {
    problem("command '" + name + "' is unknown; allowed: velocity, hold, position, normal_load");
    return false;
  }
  std::array<double*, 3> fields{&command.stage.speed, &command.stage.target, &command.normal_force};
  for (std::size_t field = 0; field < fields.size(); ++field) {
    const std::string& cell = cells[field + 2];
    const std::string column = kCommandTableColumns[field + 2];
    if (!takes[field]) {
      if (!cell.empty()) problem(name + " takes no " + column + ", got '" + cell + "'; leave it empty");
    } else if (!readNumber(cell, *fields[field])) {
      problem(name + " needs " + column + " as a number, got '" + cell + "'");
    }
  }
  return true;
}

/// Reads one row of a command table into `command`, reporting each problem, and what the run would
/// refuse of a well-formed command (`check`, if given). True if the row joins the table: a row whose time
/// is refused is left out, so that the next is compared with the last good one (`before`).
bool readCommandRow(const std::string& line, const TimedCommand* before, const CommandCheck& check,
                    const std::function<void(const std::string&)>& problem, TimedCommand& command) {
  const std::vector<std::string> cells = splitCsvLine(line);
  if (cells.size() != kCommandTableColumns.size()) {
    problem(std::to_string(kCommandTableColumns.size()) + " fields expected (" + commandTableColumns(", ") + "), got " +
            std::to_string(cells.size()) + " in '" + line + "'");
    return false;
  }
  int problems = 0;
  const std::function<void(const std::string&)> counted = [&](const std::string& what) {
    ++problems;
    problem(what);
  };
  const bool time_readable = readCommandTime(cells[0], before, command, counted);
  if (!readCommandFields(cells, command, counted)) return false;
  if (check && problems == 0) {
    const std::string refusal = check(command);
    if (!refusal.empty()) problem(refusal);
  }
  return time_readable;
}

}  // namespace

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

std::vector<TimedCommand> parseCommandTable(const std::string& csv_text, const std::string& source,
                                            const CommandCheck& check) {
  std::vector<TimedCommand> commands;
  std::vector<std::string> problems;
  std::istringstream text(csv_text);
  std::string line;
  int line_number = 0;
  const std::string where_prefix = source.empty() ? "line " : source + ", line ";
  auto problem = [&](const std::string& what) {
    problems.push_back(where_prefix + std::to_string(line_number) + ": " + what);
  };
  auto next_line = [&] {
    if (!std::getline(text, line)) return false;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  const bool header_seen = next_line();
  const std::string header = commandTableColumns(",");
  if (header_seen && line != header) {
    problem("the header must be '" + header + "', got '" + line + "'");
  }
  while (next_line()) {
    if (line.empty()) continue;
    TimedCommand command;
    if (readCommandRow(line, commands.empty() ? nullptr : &commands.back(), check, problem, command)) {
      commands.push_back(command);
    }
  }
  if (!header_seen)
    problems.push_back(where_prefix + "1: empty; a command table starts with its header '" + header + "'");
  if (!problems.empty()) throw ConfigError("command table", problems);
  return commands;
}

std::vector<TimedCommand> loadCommandTable(const std::string& path, const CommandCheck& check) {
  std::vector<std::string> problems;
  const std::string text = readTextFile(path, problems);
  if (!problems.empty()) throw ConfigError("command table", problems);
  return parseCommandTable(text, path, check);
}

std::vector<TimedCommand> protocolCommands(const LoadingProtocol& protocol, double start_normal_force) {
  std::vector<TimedCommand> commands = scheduleProtocol(protocol, 0.0, start_normal_force);
  for (TimedCommand& command : commands) command.time = stampSeconds(command.time);
  return commands;
}

void checkProtocolSteps(const LoadingProtocol& protocol, const std::string& path, const CommandCheck& check) {
  std::vector<std::string> problems;
  for (std::size_t i = 0; i < protocol.steps.size(); ++i) {
    const std::string refusal = check(stepCommand(protocol.steps[i]));
    if (!refusal.empty()) problems.push_back(path + ", steps[" + std::to_string(i) + "]: " + refusal);
  }
  if (!problems.empty()) throw ConfigError("protocol", problems);
}

}  // namespace friction
