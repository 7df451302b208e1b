// Simulation's commands (stage and F_Z) and its stop rule.
#include <cmath>
#include <sstream>

#include "friction_sim/run/simulation.h"
#include "friction_sim/scene/scene_io.h"
#include "run/fast_forward.h"

namespace friction {

void Simulation::checkStop() {
  if (finished()) return;  // the first reason stands while a caller steps on past it
  if (stopReached(scene_.stop, globalEventCount(), time_, stage_.travel())) recordStopReason();
}

[[gnu::cold]] void Simulation::recordStopReason() {
  std::ostringstream reason;
  if (scene_.stop.global_events > 0 && globalEventCount() >= scene_.stop.global_events) {
    reason << "reached " << globalEventCount() << " global slip event(s)";
  } else if (time_ >= scene_.stop.time) {
    reason << "reached the time limit of " << scene_.stop.time << " s";
  } else {
    reason << "reached the stage travel limit of " << scene_.stop.stage_travel << " m";
  }
  stop_reason_ = reason.str();
}

std::string Simulation::setStopCondition(const StopSpec& stop) {
  // Every problem, separated by " | " (a problem's own text holds "; "), so that one refusal says all that
  // must change.
  std::ostringstream reason;
  auto problem = [&reason]() -> std::ostream& { return reason << (reason.tellp() > 0 ? " | " : ""); };
  if (stop.global_events < 0) {
    problem() << "global_events " << stop.global_events << " is not allowed; allowed: >= 0 (0: not this condition)";
  }
  // A condition already met would end the run on the next step: refused, as a caller who means "now"
  // calls stop.
  if (stop.global_events > 0 && globalEventCount() >= stop.global_events) {
    problem() << "global_events " << stop.global_events << " is already reached (" << globalEventCount()
              << " so far); allowed: > " << globalEventCount() << " (0: not this condition)";
  }
  if (!(stop.time > time_)) {
    problem() << "time " << stop.time << " s is not allowed; allowed: > " << time_
              << " s, the time now (inf: not this condition)";
  }
  if (!(stop.stage_travel > stage_.travel())) {
    problem() << "stage_travel " << stop.stage_travel << " m is not allowed; allowed: > " << stage_.travel()
              << " m, the travel now (inf: not this condition)";
  }
  if (!endsTheRun(stop)) problem() << kNoEndProblem;
  if (!reason.str().empty()) return reason.str();
  scene_.stop = stop;
  stop_reason_.clear();
  checkStop();
  return {};
}

std::string Simulation::checkNormalLoad(double normal_force) const {
  std::ostringstream reason;
  if (!std::isfinite(normal_force) || normal_force <= 0.0 || normal_force > largestNormalForce(scene_)) {
    reason << "normal load " << normal_force << " N is not allowed; allowed: a finite F_Z > 0 N, at most "
           << largestNormalForce(scene_) << " N (a mean normal stress of 5 % of E: a small strain)";
  } else if (!model_->takesNormalLoadChanges()) {
    reason << "normal load " << normal_force
           << " N refused: F_Z cannot change during a run with load.top spring_mattress (its plate is placed "
              "once, when F_Z is applied); use load.top uniform";
  }
  return reason.str();
}

std::string Simulation::setNormalLoad(double normal_force) {
  std::string reason = checkNormalLoad(normal_force);
  if (!reason.empty()) return reason;
  ledger_.closeTopLoadWork(*model_, u_);
  model_->setNormalLoad(normal_force);
  power_ = acceleration(u_, v_, time_, a_);
  if (scene_.integrator.fast_forward) {
    fast_forward_->setQuasiStatic(!detector_.inEvent() && !stageTooFast() && fast_forward_->relaxToStaticEquilibrium());
  }
  return {};
}

std::string Simulation::checkCommand(const TimedCommand& command) const {
  return command.kind == TimedCommand::Kind::NormalLoad ? checkNormalLoad(command.normal_force)
                                                        : stage_.checkCommand(command.stage);
}

std::string Simulation::apply(const TimedCommand& command) {
  return command.kind == TimedCommand::Kind::NormalLoad ? setNormalLoad(command.normal_force)
                                                        : stage_.command(command.stage);
}

}  // namespace friction
