// Simulation's step groups: several plain steps of velocity Verlet in one sweep of the model.
#include <algorithm>
#include <array>
#include <optional>

#include "friction_sim/run/simulation.h"
#include "run/acceleration_strips.h"

namespace friction {

bool Simulation::mayStepInGroup(double group_before) const {
  // Without fast-forward's next try: mayJump() stays false through steps with no event.
  return scene_.integrator.scheme == IntegratorKind::VelocityVerlet && model_->successiveEvaluations() > 1 &&
         !mayJump() && contact_.slidingCount() == 0 && !detector_.inEvent() && (time_ + dt_) + dt_ < group_before;
}

void Simulation::stepInGroup(double group_before) {
  // What the steps' sweeps share, and what each step keeps for its end. Captured by reference, with
  // `this`: two pointers, which std::function keeps without allocating.
  struct Group {
    int most;
    double before;  ///< s
    VerletPasses passes;
    std::array<StepStart, kMaxGroupSteps> starts;
    std::array<std::optional<AccelerationStrips>, kMaxGroupSteps> strips;
    bool last_concluded = true;
  } group{
      std::min(model_->successiveEvaluations(), kMaxGroupSteps), group_before, VerletPasses(u_, v_, a_, dt_), {}, {}};
  group.starts[0] = stepStart();
  contact_.beginStep(u_, v_);
  const int steps =
      model_->evaluateSuccessiveInStrips(kGroupStripNodes, [this, &group](int k) -> std::optional<StripEvaluation> {
        if (k > 0) {
          // Step k − 1's interface is final. With no node sliding, finishStep has nothing to re-stick: the
          // interface's end of the step is its state update alone (settleInterface).
          advanceClock();
          if (contact_.updateStates(u_, v_, dt_, node_mass_)) {
            reapplyFriction();
            group.last_concluded = false;  // once its sums are known, below
            return std::nullopt;
          }
          // Nothing changed at the interface, so no slip event starts or ends, nothing returns to the static
          // path (which would evaluate forces while the sweeps are under way in the model's work space),
          // and the step's conclusion needs none of the sums its sweep is still adding up (F_X, the
          // viscous power).
          concludeStep(group.starts[k - 1]);
          if (k == group.most || finished() || !(time_ + dt_ < group.before)) return std::nullopt;
          group.starts[k] = stepStart();
          contact_.beginStep(u_, v_);
        }
        ForceEvaluation& evaluation = groupEvaluation(k);
        contact_.lendNormalStorage(evaluation.normal_force);
        group.strips[k].emplace(group.passes, a_, inverse_mass_, contact_, evaluation, u_, v_);
        return StripEvaluation{u_, v_, stage_.positionAfter((time_ + dt_) - time_), a_, evaluation, *group.strips[k]};
      });
  // The steps' energy, in order, now that their sums are known; the clock stands at the last one's end.
  for (int k = 0; k < steps; ++k) {
    const ForceEvaluation& evaluation = groupEvaluation(k);
    StepStart& start = group.starts[k];
    if (k > 0) start.shear_force = groupEvaluation(k - 1).shear_force;
    const double end_stage_position = k + 1 < steps ? group.starts[k + 1].stage_position : stage_.position();
    // Velocity Verlet's dissipation, as VelocityVerlet::step counts it.
    accountStep(start, evaluation.shear_force, end_stage_position, evaluation.viscous_power * dt_);
  }
  power_ = groupEvaluation(steps - 1).viscous_power;
  if (steps > 1) std::swap(evaluation_, later_evaluations_[steps - 2]);
  if (!group.last_concluded) concludeStep(group.starts[steps - 1]);
}

}  // namespace friction
