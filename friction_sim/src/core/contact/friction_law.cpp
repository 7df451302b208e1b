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

std::unique_ptr<FrictionLaw> buildFrictionLaw(const FrictionSpec& spec) {
  if (spec.law == FrictionLawKind::SlipWeakening) {
    return std::make_unique<LinearSlipWeakening>(spec.static_coefficient, spec.kinetic_coefficient,
                                                 spec.weakening_length);
  }
  return std::make_unique<AmontonsCoulomb>(spec.static_coefficient, spec.kinetic_coefficient);
}

}  // namespace friction
