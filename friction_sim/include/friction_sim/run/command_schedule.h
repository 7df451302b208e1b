// Commands waiting for their simulated time, applied as the rig node and the offline runner both apply
// them: each before the step (or fast-forward jump) that starts at or after its time, in time order,
// and a jump cut where the next one is due. One rule in one place, so that a rerun of a recorded run
// is the live run to the last digit.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <string>

#include "friction_sim/run/simulation.h"
#include "friction_sim/scene/loading_protocol.h"

namespace friction {

class CommandSchedule {
 public:
  /// `early` (s): how long before its time a command is due. 0 for commands at the times they were
  /// given (the rig's, a protocol's); half a nanosecond for times recorded rounded to whole nanoseconds
  /// (a bag's applied commands), so that a command recorded at its step's rounded time falls on that step.
  explicit CommandSchedule(double early = 0.0) : early_(early) {}

  /// Adds a command; commands at the same time are applied in the order they were added.
  void add(const TimedCommand& command) { pending_.emplace(command.time, command); }
  void clear() { pending_.clear(); }
  bool empty() const { return pending_.empty(); }
  /// s, the time of the next command (inf if none): where a jump is cut.
  double nextTime() const {
    return pending_.empty() ? std::numeric_limits<double>::infinity() : pending_.begin()->first;
  }

  /// What became of a due command: applied (`refusal` empty) or refused by the simulation.
  using Report = std::function<void(const TimedCommand& command, const std::string& refusal)>;
  /// Applies to `simulation` every command due at its time, reporting each; returns how many were applied.
  int applyDue(Simulation& simulation, const Report& report);

 private:
  std::multimap<double, TimedCommand> pending_;  ///< by simulated time (s)
  double early_;                                 ///< s
};

}  // namespace friction
