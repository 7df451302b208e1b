#include "friction_sim/instruments/instruments.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace friction {

double EnergyBudget::relativeResidual() const {
  const double scale = std::max(
      {std::abs(work_in), std::abs(elastic - initial_elastic), kinetic, friction_dissipation, viscous_dissipation});
  // Where nothing moved (a stage held from the start) every term is round-off of the stored energy, and
  // their ratio means nothing (it can read −0.13).
  if (!(scale > 1e-9 * std::abs(initial_elastic)) || scale == 0.0) return std::nan("");
  return residual() / scale;
}

double interpolationWeight(double a_time, double b_time, double t) {
  return b_time > a_time ? (t - a_time) / (b_time - a_time) : 1.0;
}

namespace {

double blend(double from, double to, double w) { return from + w * (to - from); }

/// `to` becomes from + w·(to − from), entry by entry.
void blend(const std::vector<double>& from, std::vector<double>& to, double w) {
  for (std::size_t i = 0; i < to.size() && i < from.size(); ++i) to[i] = blend(from[i], to[i], w);
}

/// `b` moved to time t, and b's weight at t against `a` (the rest is blended by the caller).
template <class Reading>
std::pair<Reading, double> startAt(const Reading& a, const Reading& b, double t) {
  Reading out = b;
  out.time = t;
  return {std::move(out), interpolationWeight(a.time, b.time, t)};
}

void blend(const GaugeStresses& from, GaugeStresses& to, double w) {
  blend(from.sigma_xx, to.sigma_xx, w);
  blend(from.sigma_zz, to.sigma_zz, w);
  blend(from.tau_xz, to.tau_xz, w);
}
}  // namespace

LoadCellReading interpolate(const LoadCellReading& a, const LoadCellReading& b, double t) {
  auto [out, w] = startAt(a, b, t);
  out.stage_position = blend(a.stage_position, b.stage_position, w);
  out.shear_force = blend(a.shear_force, b.shear_force, w);
  out.normal_force = blend(a.normal_force, b.normal_force, w);
  out.interface_normal_sum = blend(a.interface_normal_sum, b.interface_normal_sum, w);
  return out;
}

StageStateReading interpolate(const StageStateReading& a, const StageStateReading& b, double t) {
  StageStateReading at{interpolate(a.cells, b.cells, t), t < b.cells.time ? a.stage : b.stage};
  const double w = interpolationWeight(a.cells.time, b.cells.time, t);
  at.stage.travel = a.stage.travel + w * (b.stage.travel - a.stage.travel);
  return at;
}

GaugeProfile interpolate(const GaugeProfile& a, const GaugeProfile& b, double t) {
  auto [out, w] = startAt(a, b, t);
  blend(a.stress, out.stress, w);
  return out;
}

InterfaceFrame interpolate(const InterfaceFrame& a, const InterfaceFrame& b, double t) {
  auto [out, w] = startAt(a, b, t);
  if (t < b.time) out.state = a.state;
  for (auto field : {&InterfaceFrame::slip_velocity, &InterfaceFrame::slip, &InterfaceFrame::normal_force,
                     &InterfaceFrame::friction_force, &InterfaceFrame::normal_stress, &InterfaceFrame::shear_stress,
                     &InterfaceFrame::static_coefficient}) {
    blend(a.*field, out.*field, w);
  }
  return out;
}

LatticeSnapshot interpolate(const LatticeSnapshot& a, const LatticeSnapshot& b, double t) {
  auto [out, w] = startAt(a, b, t);
  if (t < b.time) out.interface_state = a.interface_state;
  for (auto field : {&LatticeSnapshot::x, &LatticeSnapshot::z, &LatticeSnapshot::speed}) blend(a.*field, out.*field, w);
  blend(a.stress, out.stress, w);
  out.stage_position = blend(a.stage_position, b.stage_position, w);
  out.normal_force = blend(a.normal_force, b.normal_force, w);
  return out;
}

}  // namespace friction
