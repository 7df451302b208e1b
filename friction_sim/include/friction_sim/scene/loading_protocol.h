// The loading protocol a controller runs (ROS-free): ramp F_Z to a target, hold, drive the stage at V,
// stop and go, move to a position; and when to end the run. Read from YAML, it becomes a schedule of
// commands, each stamped with the simulated time at which it takes effect, so that a run is
// deterministic however late the commands travel.
//
//   steps:
//     - {action: normal_load, normal_force: 1920, ramp_time: 0.005}  # N, s
//     - {action: hold, duration: 0.002}                               # s
//     - {action: drive, speed: 4.0e-4, duration: .inf}                # m/s, s
//   end: {global_events: 4, stage_travel: .inf, time: .inf}           # count, m, s
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "friction_sim/stage/stage.h"

namespace friction {

enum class ProtocolAction { NormalLoad, Hold, Drive, MoveTo };

struct ProtocolStep {
  ProtocolAction action = ProtocolAction::Drive;  ///< what the step does: normal_load, hold, drive or move_to
  double normal_force = 0.0;                      ///< N, F_Z to reach (normal_load)
  /// s, F_Z ramps over this time (normal_load; 0 = at once): a staircase of ramp_commands equal steps,
  /// the k-th at (k − 1)/n of it, so that F_Z reaches its target at (n − 1)/n·ramp_time.
  double ramp_time = 0.0;
  double speed = 4.0e-4;  ///< m/s, stage speed (drive, signed) or travel speed (move_to)
  double target = 0.0;    ///< m, stage position (move_to)
  double duration = std::numeric_limits<double>::infinity();  ///< s, how long the step lasts (hold, drive, move_to)
};

struct ProtocolEnd {
  int global_events = 0;  ///< end after this many global slip events (0 = not this condition)
  double stage_travel = std::numeric_limits<double>::infinity();  ///< m
  double time = std::numeric_limits<double>::infinity();          ///< s since the protocol started
  /// The run's stop condition for a protocol started at `start_time` (s of simulated time).
  StopSpec stopFrom(double start_time) const { return {global_events, start_time + time, stage_travel}; }
};

struct LoadingProtocol {
  std::vector<ProtocolStep> steps{ProtocolStep{}};  ///< run in order; the last one persists
  ProtocolEnd end;                                  ///< when the protocol, and the run, ends
  int ramp_commands = 20;                           ///< F_Z commands (equal steps) per ramp, n >= 1
};

/// A command to the rig at a simulated time.
struct TimedCommand {
  enum class Kind { Stage, NormalLoad };
  double time = 0.0;          ///< s, simulated
  Kind kind = Kind::Stage;    ///< a stage command, or a new F_Z
  StageCommand stage;         ///< the stage's mode, speed and target (kind Stage)
  double normal_force = 0.0;  ///< N
};

/// Throws ConfigError listing every problem.
LoadingProtocol parseProtocol(const std::string& yaml_text, const std::string& source = "");
LoadingProtocol loadProtocol(const std::string& path);

/// What `step` acts with, at time 0: a normal_load step's final F_Z (its ramp's steps lie between the F_Z
/// before and that), a hold, drive or move_to step's stage command.
TimedCommand stepCommand(const ProtocolStep& step);

/// The protocol's commands from `start_time` (s), ramps starting at F_Z = `start_normal_force` (N);
/// it ends with the first step of infinite duration. The protocol drives the stage from its start: one
/// that begins with normal_load steps holds the stage until its first stage step (one of normal_load
/// steps alone holds it throughout).
std::vector<TimedCommand> scheduleProtocol(const LoadingProtocol& protocol, double start_time,
                                           double start_normal_force);

/// s, `seconds` as a ROS stamp carries it, in whole nanoseconds (as ros::Time(seconds).toSec()): the time
/// at which the rig applies a controller's command.
double stampSeconds(double seconds);

/// The cells of one line of the rig's CSV files (no quoting: no cell holds a comma); a trailing comma
/// ends in an empty cell.
std::vector<std::string> splitCsvLine(const std::string& line);

/// The commands of a command table, as rig_report writes a bag's applied commands (stage_commands.csv)
/// for friction_run --commands:
///
///   time_s,command,speed_m_s,target_m,normal_force_N
///   0.000000000,hold,,,
///   0.005000000,velocity,0.0004,,
///   0.010000000,position,0.0004,0.00012,
///   0.012000000,normal_load,,,2500
///
/// One row per command, in time order (s, simulated); `command` is velocity (speed), hold, position
/// (speed, target) or normal_load (normal_force), and the fields its mode does not use stay empty.
/// `check`, if given, says why a well-formed command would be refused (empty if not), as the run's
/// simulation does. Throws ConfigError listing every problem with its line.
using CommandCheck = std::function<std::string(const TimedCommand&)>;
std::vector<TimedCommand> parseCommandTable(const std::string& csv_text, const std::string& source = "",
                                            const CommandCheck& check = nullptr);
std::vector<TimedCommand> loadCommandTable(const std::string& path, const CommandCheck& check = nullptr);

/// The protocol's commands as the stage controller sends them from t = 0, ramps starting at F_Z =
/// `start_normal_force` (N): each at the time its stamp carries (stampSeconds).
std::vector<TimedCommand> protocolCommands(const LoadingProtocol& protocol, double start_normal_force);

/// Throws ConfigError listing every step of `protocol` (read from `path`) that `check` refuses what it acts
/// with (stepCommand), before anything runs.
void checkProtocolSteps(const LoadingProtocol& protocol, const std::string& path, const CommandCheck& check);

}  // namespace friction
