#include "friction_sim/stage/stage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "friction_sim/scene/config_error.h"

namespace friction {

Stage::Stage(const StageSpec& spec, double time_step) : spec_(spec), time_step_(time_step) { enterSegment(0); }

void Stage::enterSegment(std::size_t index) {
  segment_ = index;
  segment_elapsed_ = 0.0;
  const StageSegment& segment = spec_.program[index];
  current_ = StageCommand{segment.mode, segment.speed, segment.target};
}

double Stage::velocity() const {
  switch (current_.mode) {
    case StageMode::Velocity:
      return current_.speed;
    case StageMode::Position:
      if (position_ == current_.target) return 0.0;
      return position_ < current_.target ? current_.speed : -current_.speed;
    case StageMode::Hold:
      break;
  }
  return 0.0;
}

double Stage::positionAfter(double lead) const {
  const double next = position_ + velocity() * lead;
  if (current_.mode != StageMode::Position) return next;
  const bool passed = (next - current_.target) * (position_ - current_.target) < 0.0;
  return passed ? current_.target : next;
}

double Stage::timeToNextChange() const {
  double time = std::numeric_limits<double>::infinity();
  if (following_program_ && segment_ + 1 < spec_.program.size()) {
    time = spec_.program[segment_].duration - segment_elapsed_;
  }
  const double speed = std::abs(velocity());
  if (current_.mode == StageMode::Position && speed > 0.0) {
    time = std::min(time, std::abs(current_.target - position_) / speed);
  }
  return std::max(time, 0.0);
}

std::string Stage::checkCommand(const StageCommand& command) const {
  std::ostringstream reason;
  if (!std::isfinite(command.speed) || !std::isfinite(command.target)) {
    reason << "speed " << refusedValueText(command.speed) << " m/s and target " << refusedValueText(command.target)
           << " m must be finite";
  } else if (std::abs(command.speed) > spec_.max_speed) {
    reason << "speed " << command.speed << " m/s exceeds the stage's max_speed " << spec_.max_speed << " m/s";
  } else if (command.mode == StageMode::Position && command.speed <= 0.0) {
    reason << "a position command needs a travel speed > 0 m/s, got " << command.speed;
  }
  return reason.str();
}

std::string Stage::command(const StageCommand& command) {
  std::string reason = checkCommand(command);
  if (reason.empty()) {
    current_ = command;
    following_program_ = false;
  }
  return reason;
}

void Stage::advance(double duration) {
  const double next = positionAfter(duration);
  travel_ += std::abs(next - position_);
  position_ = next;
  if (!following_program_) return;
  segment_elapsed_ += duration;
  // Half a time step, not half of `duration`: a jump stopped short of a threshold may end well before
  // the segment does, and the segment must not be cut short by half the jump.
  if (segment_elapsed_ + 0.5 * time_step_ >= spec_.program[segment_].duration && segment_ + 1 < spec_.program.size()) {
    enterSegment(segment_ + 1);
  }
}

}  // namespace friction
