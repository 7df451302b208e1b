#include "friction_sim/instruments.h"

#include <algorithm>
#include <cmath>

namespace friction {

double EnergyBudget::relativeResidual() const {
  const double scale = std::max({std::abs(work_in), std::abs(elastic - initial_elastic), kinetic,
                                 friction_dissipation, viscous_dissipation, 1e-300});
  return residual() / scale;
}

LoadCellReading interpolate(const LoadCellReading& a, const LoadCellReading& b, double t) {
  const double w = b.time > a.time ? (t - a.time) / (b.time - a.time) : 1.0;
  LoadCellReading out = b;
  out.time = t;
  out.stage_position = a.stage_position + w * (b.stage_position - a.stage_position);
  out.shear_force = a.shear_force + w * (b.shear_force - a.shear_force);
  out.normal_force = a.normal_force + w * (b.normal_force - a.normal_force);
  out.interface_normal_sum = a.interface_normal_sum + w * (b.interface_normal_sum - a.interface_normal_sum);
  return out;
}

GaugeProfile interpolate(const GaugeProfile& a, const GaugeProfile& b, double t) {
  const double w = b.time > a.time ? (t - a.time) / (b.time - a.time) : 1.0;
  GaugeProfile out = b;
  out.time = t;
  auto blend = [w](const std::vector<double>& from, std::vector<double>& to) {
    for (std::size_t i = 0; i < to.size() && i < from.size(); ++i) to[i] = from[i] + w * (to[i] - from[i]);
  };
  blend(a.stress.sigma_xx, out.stress.sigma_xx);
  blend(a.stress.sigma_zz, out.stress.sigma_zz);
  blend(a.stress.tau_xz, out.stress.tau_xz);
  return out;
}

}  // namespace friction
