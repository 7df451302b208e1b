#include "friction_sim/run/command_schedule.h"

namespace friction {

int CommandSchedule::applyDue(Simulation& simulation, const Report& report) {
  int applied = 0;
  while (!pending_.empty() && pending_.begin()->first <= simulation.time() + early_) {
    const TimedCommand command = pending_.begin()->second;
    pending_.erase(pending_.begin());
    const std::string refusal = simulation.apply(command);
    if (refusal.empty()) ++applied;
    report(command, refusal);
  }
  return applied;
}

}  // namespace friction
