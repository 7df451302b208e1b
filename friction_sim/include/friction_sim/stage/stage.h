// The loading stage: the far end of the pusher spring, at position X_s (m, along x). It follows a
// program of segments from the scene until a command (from a controller) replaces the program.
#pragma once

#include <string>

#include "friction_sim/scene/scene.h"

namespace friction {

struct StageCommand {
  StageMode mode = StageMode::Hold;
  double speed = 0.0;   ///< m/s, velocity (velocity mode, may be negative) or travel speed (position mode)
  double target = 0.0;  ///< m, position to reach (position mode)
};

class Stage {
 public:
  /// `time_step` (s) is the run's: a program segment ends on the step that ends nearest to its end
  /// (immune to round-off in the sum of the steps), also when the stage is advanced by a longer jump.
  Stage(const StageSpec& spec, double time_step);

  double position() const { return position_; }             ///< m, X_s
  double velocity() const;                                  ///< m/s, dX_s/dt now
  double travel() const { return travel_; }                 ///< m, total distance moved
  const StageCommand& current() const { return current_; }  ///< what the stage is doing now
  /// m, where the stage will be `lead` seconds from now if nothing changes (for stages within a step).
  double positionAfter(double lead) const;
  /// s until the stage's motion changes by itself: its program segment ends or it reaches its target.
  double timeToNextChange() const;

  /// Why `command` would be refused (empty if acceptable): non-finite values, speed beyond max_speed.
  std::string checkCommand(const StageCommand& command) const;
  /// Replaces the program by `command`; returns the refusal reason, or empty if applied.
  std::string command(const StageCommand& command);
  /// Moves the stage on by `duration` (s): one time step, or a fast-forward jump that ends at or before
  /// the end of the current segment.
  void advance(double duration);

 private:
  void enterSegment(std::size_t index);

  StageSpec spec_;
  StageCommand current_;
  std::size_t segment_ = 0;
  bool following_program_ = true;
  double time_step_;              ///< s, the run's time step
  double segment_elapsed_ = 0.0;  ///< s
  double position_ = 0.0;
  double travel_ = 0.0;
};

}  // namespace friction
