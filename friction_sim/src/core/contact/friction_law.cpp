#include "friction_sim/contact/friction_law.h"

#include <algorithm>
#include <cmath>

namespace friction {

AmontonsCoulomb::AmontonsCoulomb(double static_coefficient, double kinetic_coefficient)
    : static_(static_coefficient), kinetic_(kinetic_coefficient) {}

LinearSlipWeakening::LinearSlipWeakening(double static_coefficient, double kinetic_coefficient, double weakening_length)
    : static_(static_coefficient), kinetic_(kinetic_coefficient), weakening_length_(weakening_length) {}

double LinearSlipWeakening::slidingCoefficient(int node) const {
  if (weakening_length_ <= 0.0) return kinetic_;
  const double progress = std::min(slip_since_unstick_[node] / weakening_length_, 1.0);
  return static_ - (static_ - kinetic_) * progress;
}

void LinearSlipWeakening::onSlip(int node, double slip) { slip_since_unstick_[node] += std::abs(slip); }

void RateAndState::resize(int node_count) {
  age_.assign(node_count, spec_.initial_age);
  since_.assign(node_count, now_);
}

void RateAndState::settle(int node) {
  age_[node] = age(node);
  since_[node] = now_;
}

void RateAndState::onSlip(int node, double slip) {
  age_[node] = spec_.ageAfterSlip(age_[node], slip, now_ - since_[node]);
  since_[node] = now_;
}

double RateAndState::endSpeed(int node, double reach, double resistance, double start_speed) const {
  const double at_rest = coefficientAt(node, 0.0);
  const double fastest = reach - resistance * at_rest;
  if (fastest <= 0.0) return fastest;
  // In x = ln(1 + y/v*), y + resistance·µ(y) = reach reads v*(e^x − 1) + resistance·(µ(0) + a·x) = reach:
  // convex and increasing in x. Newton's method converges monotonically from above, and from below its
  // first step lands above. In a slide the speed before the kick is close: two or three iterations do.
  // The speed with µ(0) bounds the root from above.
  const double v_star = spec_.reference_speed, a = spec_.direct_effect;
  const double highest = std::log1p(fastest / v_star);
  double x = start_speed > 0.0 && start_speed < fastest ? std::log1p(start_speed / v_star) : highest;
  double speed = 0.0;
  constexpr int kMaxIterations = 200;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    speed = v_star * std::expm1(x);
    const double excess = speed + resistance * (at_rest + a * x) - reach;
    // The slope needs a few digits only: v*·e^x from the speed at hand rather than another exponential.
    const double step = excess / (speed + v_star + resistance * a);
    // Below the root only at the guess: past the first step, a negative one is round-off.
    if (!(step > 1e-15 * x) && !(iteration == 0 && step < 0.0)) break;
    x = std::min(x - step, highest);
  }
  return speed;
}

void RateAndState::onLanding(int node) {
  age_[node] = 0.0;
  since_[node] = now_;
}

std::vector<double> RateAndState::stateNumbers() const {
  std::vector<double> numbers(age_.size());
  for (std::size_t node = 0; node < age_.size(); ++node) numbers[node] = age(static_cast<int>(node));
  return numbers;
}

std::unique_ptr<FrictionLaw> buildFrictionLaw(const FrictionSpec& spec) {
  if (spec.law == FrictionLawKind::RateState) return std::make_unique<RateAndState>(spec.rate_state);
  if (spec.law == FrictionLawKind::SlipWeakening) {
    return std::make_unique<LinearSlipWeakening>(spec.static_coefficient, spec.kinetic_coefficient,
                                                 spec.weakening_length);
  }
  return std::make_unique<AmontonsCoulomb>(spec.static_coefficient, spec.kinetic_coefficient);
}

}  // namespace friction
