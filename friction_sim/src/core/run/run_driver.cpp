#include "friction_sim/run/run_driver.h"

#include <algorithm>
#include <sstream>

namespace friction {

CameraStream::CameraStream(SampleRates rates, Sink sink)
    : rates_(rates), next_(1.0 / rates.idle), sink_(std::move(sink)) {}

void CameraStream::before(const Simulation& simulation, bool /*commands_applied*/) {
  if (simulation.mayJump()) before_ = simulation.interfaceFrame();
}

void CameraStream::after(const Simulation& simulation, bool jumped) {
  const double t = simulation.time();
  if (jumped) {
    const InterfaceFrame end = simulation.interfaceFrame();
    for (; next_ <= t; next_ += 1.0 / rates_.idle) sink_(interpolate(before_, end, next_));
  }
  if (simulation.interfaceChangedLastStep() || t >= next_) {
    sink_(simulation.interfaceFrame());
    next_ = t + 1.0 / (simulation.inEvent() ? rates_.during_events : rates_.idle);
  }
}

void EventStream::after(const Simulation& simulation, bool /*jumped*/) {
  if (started_ && simulation.eventStartedLastStep()) started_(simulation);
  if (ended_ && simulation.eventEndedLastStep()) ended_(simulation, simulation.events().back());
}

RunDriver::RunDriver(const Scene& scene, double stability_limit, RunOptions options)
    : simulation_(scene, stability_limit), options_(options), schedule_(options.command_early) {
  simulation_.setThreads(options.threads);
}

std::string RunDriver::setRunEnd(const StopSpec& stop) {
  std::string refusal = simulation_.setStopCondition(stop);
  if (refusal.empty()) run_end_set_ = true;
  return refusal;
}

std::size_t RunDriver::scheduleAll(const std::vector<TimedCommand>& commands) {
  for (const TimedCommand& command : commands) schedule(command);
  return commands.size();
}

std::string RunDriver::checkCommandTime(const TimedCommand& command) const {
  const double end = simulation_.scene().stop.time;
  if ((options_.stop_at_scene_end || run_end_set_) && command.time > end) {
    std::ostringstream reason;
    reason << "stamped at t = " << command.time << " s, after the run's end at t = " << end
           << " s: it would never be applied";
    return reason.str();
  }
  return {};
}

std::string RunDriver::checkCommand(const TimedCommand& command) const {
  std::string refusal = simulation_.checkCommand(command);
  return refusal.empty() ? checkCommandTime(command) : refusal;
}

CommandCheck RunDriver::commandCheck() const {
  return [this](const TimedCommand& command) { return checkCommand(command); };
}

std::size_t RunDriver::scheduleCommandTable(const std::string& path) {
  return scheduleAll(loadCommandTable(path, commandCheck()));
}

std::size_t RunDriver::scheduleProtocol(const LoadingProtocol& protocol, const std::string& path) {
  checkProtocolSteps(protocol, path, commandCheck());
  return scheduleAll(protocolCommands(protocol, simulation_.scene().load.normal_force));
}

double RunDriver::jumpEnd() const {
  double end = schedule_.nextTime();
  // A rest with no end (the stage still, nothing due, no program segment to end) is cut at frames too,
  // or its jump would have no end. Not a rest that ends: cutting a jump changes the run in its last digits.
  const Stage& stage = simulation_.stage();
  const bool endless_rest = stage.velocity() == 0.0 && schedule_.empty() && std::isinf(stage.timeToNextChange());
  if (!options_.cut_jumps_at_frames && !endless_rest) return end;
  const double command = end;
  for (const auto& stream : streams_) {
    // A frame within a step of the command is no cut: the jump would stop a hair short of the command,
    // and the step after it would pass it.
    if (stream->cutsJumps() && stream->nextTime() < command - simulation_.timeStep()) {
      end = std::min(end, stream->nextTime());
    }
  }
  return end;
}

void RunDriver::advance() {
  const bool commands_applied = schedule_.applyDue(simulation_, command_due_) > 0;
  const double until = jumpEnd();
  // Plain steps are taken several at once only where none of them ends at or after a stream's sample
  // time: every stream sees the steps it samples.
  double group_before = until;
  for (const auto& stream : streams_) group_before = std::min(group_before, stream->nextTime());
  for (const auto& stream : streams_) stream->before(simulation_, commands_applied);
  const long long jumps = simulation_.jumps();
  simulation_.advance(until, group_before);
  const bool jumped = simulation_.jumps() != jumps;
  for (const auto& stream : streams_) stream->after(simulation_, jumped);
}

StageStateReading stageState(const Simulation& simulation) {
  const Stage& stage = simulation.stage();
  return {simulation.loadCells(), {stage.current().mode, stage.velocity(), stage.current().target, stage.travel()}};
}

}  // namespace friction
