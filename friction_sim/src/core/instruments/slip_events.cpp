#include "friction_sim/instruments/slip_events.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "friction_sim/model/lattice_2d.h"

namespace friction {

double SlipEvent::meanSlip() const {
  double sum = 0.0;
  int slipped = 0;
  for (std::size_t node = 0; node < node_slip.size() && node < first_unstick_time.size(); ++node) {
    if (std::isnan(first_unstick_time[node])) continue;
    sum += node_slip[node];
    ++slipped;
  }
  return slipped > 0 ? sum / slipped : std::numeric_limits<double>::quiet_NaN();
}

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

SlipEventDetector::SlipEventDetector(const Model& model, int front_fit_nodes, double longitudinal_speed,
                                     double slider_length, SlipCriterion criterion)
    : positions_(model.interfacePositions()),
      fit_nodes_(front_fit_nodes),
      longitudinal_speed_(longitudinal_speed),
      slider_length_(slider_length),
      criterion_(criterion) {
  for (int node = 0; node < model.interfaceNodeCount(); ++node) dofs_.push_back(model.interfaceDof(node));
  onset_u_.resize(positions_.size());
  began_at_.resize(positions_.size());
  quiet_u_.resize(positions_.size());
  slip_speed_.assign(positions_.size(), 0.0);
}

void SlipEventDetector::watchSlip(double step_start, double dt, const ContactInterface& contact, const Vector& v) {
  began_.clear();
  last_ceased_ = kNaN;
  auto note_ceased = [&](double time) {
    last_ceased_ = std::isnan(last_ceased_) ? time : std::max(last_ceased_, time);
  };
  if (criterion_.speed <= 0.0) {
    // Every sliding node slips: the interface's own transitions, at their times within the step.
    auto transition_time = [&](int node) { return step_start + contact.transitionFraction(node) * dt; };
    for (int node : contact.unstuckLastStep()) {
      began_.push_back(node);
      began_at_[node] = transition_time(node);
    }
    for (int node : contact.restuckLastStep()) note_ceased(transition_time(node));
    slipping_count_ = static_cast<std::size_t>(contact.slidingCount());
    return;
  }
  // Crossings of the speed, linear in time within the step.
  slipping_count_ = 0;
  auto crossing = [&](double from, double to) {
    return to == from ? step_start + dt
                      : step_start + std::clamp((criterion_.speed - from) / (to - from), 0.0, 1.0) * dt;
  };
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const auto state = contact.state(static_cast<int>(node));
    const double velocity = v[dofs_[node]];
    const double speed = state == ContactState::Sliding ? std::abs(velocity) : 0.0;
    const bool slipping = criterion_.slipping(state, velocity);
    // A node not sliding has speed 0, below the criterion's: its speed alone says whether it slipped.
    const bool was_slipping = slip_speed_[node] >= criterion_.speed;
    if (slipping && !was_slipping) {
      began_.push_back(static_cast<int>(node));
      began_at_[node] = crossing(slip_speed_[node], speed);
    } else if (!slipping && was_slipping) {
      note_ceased(crossing(slip_speed_[node], speed));
    }
    slip_speed_[node] = speed;
    slipping_count_ += slipping;
  }
}

void SlipEventDetector::startEvent(double step_start, double dt, const ContactInterface& contact, const Vector& u,
                                   const StepLoads& loads) {
  in_event_ = true;
  const std::size_t n = positions_.size();
  current_ = SlipEvent{};
  current_.index = tally_.events;
  current_.onset_time = step_start + dt;
  for (int node : began_) current_.onset_time = std::min(current_.onset_time, began_at_[node]);
  current_.onset_shear_force = loads.shearAt(current_.onset_time, step_start, dt);
  current_.peak_shear_force = current_.onset_shear_force;
  slipped_ = 0;
  in_contact_.start(n);
  current_.onset_normal_force = loads.normal;
  shear_impulse_ = 0.0;
  normal_impulse_ = 0.0;
  quiet_since_ = kNaN;
  current_.first_unstick_time.assign(n, kNaN);
  current_.last_slip_time.assign(n, kNaN);
  current_.peak_slip_velocity.assign(n, 0.0);
  double sum = 0.0;
  for (int node : began_) sum += positions_[node];
  current_.nucleation_position = sum / began_.size();
  // Slip counts from where the nodes were before this step, including what unsticking caught up.
  for (std::size_t node = 0; node < n; ++node) onset_u_[node] = contact.stepStartPosition(static_cast<int>(node), u);
}

bool SlipEventDetector::update(double step_start, double dt, const ContactInterface& contact, const Vector& u,
                               const Vector& v, const StepLoads& loads) {
  watchSlip(step_start, dt, contact, v);
  quiet_began_ = false;
  auto shear_at = [&](double time) { return loads.shearAt(time, step_start, dt); };
  if (!in_event_ && !began_.empty()) startEvent(step_start, dt, contact, u, loads);
  if (!in_event_) return false;
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const ContactState state = contact.state(static_cast<int>(node));
    if (state != ContactState::Sliding) continue;
    const double velocity = v[dofs_[node]];
    double& peak = current_.peak_slip_velocity[node];
    peak = std::max(peak, std::abs(velocity));
    if (criterion_.slipping(state, velocity)) current_.last_slip_time[node] = step_start + dt;
  }
  in_contact_.note(static_cast<std::size_t>(contact.detachedCount()),
                   [&contact](std::size_t node) { return contact.state(static_cast<int>(node)); });
  const bool was_global = slipped_ == in_contact_.count();
  double last_first_unstick = step_start;  // of the nodes slipping for the first time in this step
  for (int node : began_) {
    if (!std::isnan(current_.first_unstick_time[node])) continue;
    current_.first_unstick_time[node] = began_at_[node];
    last_first_unstick = std::max(last_first_unstick, current_.first_unstick_time[node]);
    ++slipped_;
    in_contact_.touch(static_cast<std::size_t>(node));
  }
  const double step_end = step_start + dt;
  const bool quiet_before = !std::isnan(quiet_since_);
  if (slipping_count_ > 0) {
    quiet_since_ = kNaN;
  } else if (!quiet_before) {
    quiet_since_ = std::isnan(last_ceased_) ? step_end : std::max(step_start, last_ceased_);
  }
  const bool quiet_began = !quiet_before && !std::isnan(quiet_since_);
  quiet_began_ = quiet_began;
  // The part of the step up to where a quiet spell begins, or all of it: the event's end, if the spell lasts.
  const double watch_end = quiet_began ? quiet_since_ : step_end;
  // The peak is watched until the whole interface has slipped. F_X is linear across the step, so its
  // value where this step's part of the watch ends bounds it (the start was noted at the onset or by
  // the step before).
  const bool quiet_throughout = quiet_before && !std::isnan(quiet_since_);
  if (!was_global && !quiet_throughout) {
    notePeak(shear_at(slipped_ == in_contact_.count() ? last_first_unstick : watch_end));
  }
  // The step inside the event, F_X linear across it as in shear_at; a quiet spell's part is counted
  // apart, for the event goes on if a node slips again.
  auto add_impulse = [&](double from, double to) {
    if (to <= from) return;
    shear_impulse_ += 0.5 * (shear_at(from) + shear_at(to)) * (to - from);
    normal_impulse_ += loads.normal * (to - from);
  };
  const double from = std::max(step_start, current_.onset_time);
  add_impulse(from, watch_end);
  if (quiet_began) {
    quiet_step_end_ = step_end;
    noteQuietStart(shear_at(quiet_since_), u);
    add_impulse(std::max(from, watch_end), step_end);
  }
  if (std::isnan(quiet_since_) || step_end - quiet_step_end_ < criterion_.quiet_time) return false;
  finish();
  return true;
}

void SlipEventDetector::noteQuietStart(double shear_force, const Vector& u) {
  quiet_shear_force_ = shear_force;
  quiet_shear_impulse_ = shear_impulse_;
  quiet_normal_impulse_ = normal_impulse_;
  for (std::size_t node = 0; node < quiet_u_.size(); ++node) quiet_u_[node] = u[dofs_[node]];
}

void SlipEventDetector::notePeak(double shear_force) {
  if (std::abs(shear_force) > std::abs(current_.peak_shear_force)) current_.peak_shear_force = shear_force;
}

bool SlipEventDetector::finishUnfinished(double time, double shear_force, const Vector& u) {
  if (!in_event_) return false;
  if (std::isnan(quiet_since_)) {
    quiet_since_ = time;
    noteQuietStart(shear_force, u);
  }
  current_.unfinished = true;
  finish();
  return true;
}

void SlipEventDetector::finish() {
  in_event_ = false;
  SlipEvent& event = current_;
  event.end_time = quiet_since_;
  event.end_shear_force = quiet_shear_force_;
  const double duration = event.end_time - event.onset_time;
  event.mean_shear_force = duration > 0.0 ? quiet_shear_impulse_ / duration : event.onset_shear_force;
  event.mean_normal_force = duration > 0.0 ? quiet_normal_impulse_ / duration : event.onset_normal_force;
  const std::size_t n = positions_.size();
  event.node_slip.resize(n);
  for (std::size_t node = 0; node < n; ++node) event.node_slip[node] = quiet_u_[node] - onset_u_[node];
  measureExtent(event, positions_, slider_length_, in_contact_.count());
  measureFronts(event, positions_, fit_nodes_, longitudinal_speed_);
  event.kind = classifySlipEvent(event, tally_.global_events > 0);
  tally_.add(event, slider_length_);
  if (events_.size() == 2 * kKeptEvents) events_.erase(events_.begin(), events_.begin() + kKeptEvents);
  events_.push_back(std::move(event));
}

void EventTally::add(const SlipEvent& event, double slider_length) {
  ++events;
  last_event_unfinished = event.unfinished;
  const double numbers[] = {event.onset_time,       event.end_time,       event.onset_shear_force,
                            event.mean_shear_force, event.rupture_length, event.nucleation_position};
  hash.mix(numbers, sizeof numbers);
  hash.mix(event.node_slip.data(), sizeof(double) * event.node_slip.size());
  const bool first_global = event.kind == SlipEventKind::Global && global_events == 0;
  if (event.kind == SlipEventKind::Global) ++global_events;
  switch (event.kind) {
    case SlipEventKind::Global:
      if (first_global) {
        static_friction_macro = event.peakShearRatio();
        kinetic_friction_macro = event.meanShearRatio();
      }
      break;
    case SlipEventKind::BackSlip:
      ++back_slips;
      break;
    case SlipEventKind::SingleNodeSlip:
    case SlipEventKind::Precursor:
      ++precursors;
      if (event.kind == SlipEventKind::SingleNodeSlip) ++single_node_precursors;
      precursor_points.push_back(
          {event.onset_shear_force / event.onset_normal_force, event.rupture_length / slider_length});
      break;
    case SlipEventKind::AfterGlobal:
      break;
  }
}

SlipEventKind classifySlipEvent(const SlipEvent& event, bool after_a_global_event) {
  if (event.global) return SlipEventKind::Global;
  if (after_a_global_event) return SlipEventKind::AfterGlobal;
  if (event.backSlip()) return SlipEventKind::BackSlip;
  return event.rupture_length == 0.0 ? SlipEventKind::SingleNodeSlip : SlipEventKind::Precursor;
}

FitWindow frontFitWindow(int fit_nodes) {
  const int nodes = std::max(fit_nodes, 2);
  return {nodes / 2, (nodes - 1) / 2};
}

std::vector<double> frontSpeeds(const std::vector<double>& positions, const std::vector<double>& first_unstick_time,
                                int fit_nodes) {
  const int n = static_cast<int>(positions.size());
  std::vector<double> speed(n, kNaN);
  const auto [behind, ahead] = frontFitWindow(fit_nodes);
  for (int centre = 0; centre < n; ++centre) {
    if (std::isnan(first_unstick_time[centre])) continue;
    // Fit over the slipped nodes of the window around the centre, not across unslipped gaps.
    int low = centre, high = centre;
    while (low > 0 && centre - low < behind && !std::isnan(first_unstick_time[low - 1])) --low;
    while (high + 1 < n && high - centre < ahead && !std::isnan(first_unstick_time[high + 1])) ++high;
    if (high == low) continue;
    double mean_x = 0.0, mean_t = 0.0;
    const int count = high - low + 1;
    for (int i = low; i <= high; ++i) {
      mean_x += positions[i] / count;
      mean_t += first_unstick_time[i] / count;
    }
    double sxx = 0.0, sxt = 0.0;
    for (int i = low; i <= high; ++i) {
      sxx += (positions[i] - mean_x) * (positions[i] - mean_x);
      sxt += (positions[i] - mean_x) * (first_unstick_time[i] - mean_t);
    }
    const double slowness = std::abs(sxt / sxx);
    speed[centre] = slowness > 0.0 ? 1.0 / slowness : std::numeric_limits<double>::infinity();
  }
  return speed;
}

namespace {
/// c_R/c_S for the lattice's ν = 1/3 (MODEL.md §2), the root of the Rayleigh equation.
constexpr double kRayleighFraction = 0.919;
}  // namespace

SlipCriterion slipCriterion(const Scene& scene) {
  const double speed = scene.instruments.event_slip_speed;
  return {speed, speed > 0.0 ? scene.geometry.length / waveSpeeds(scene).shear : 0.0};
}

WaveSpeeds waveSpeeds(const Scene& scene) {
  const double E = scene.material.youngs_modulus, rho = scene.material.density;
  if (scene.model == ModelKind::Chain1D) {
    const double bar = std::sqrt(E / rho);
    return {bar, bar, 0.0};
  }
  const double shear = std::sqrt(Lattice2D::shearModulus(scene) / rho);
  return {std::sqrt(3.0) * shear, shear, kRayleighFraction * shear};
}

FrontSpeedSummary summarizeFrontSpeeds(const std::vector<double>& front_speed,
                                       const std::vector<double>& first_unstick_time, int fit_nodes,
                                       double longitudinal_speed) {
  FrontSpeedSummary summary;
  const int n = static_cast<int>(front_speed.size());
  const bool limit_known = longitudinal_speed > 0.0;
  auto too_fast = [&](int node) {
    const double speed = front_speed[node];
    return !std::isnan(speed) && (!std::isfinite(speed) || (limit_known && speed > longitudinal_speed));
  };
  // The patches: each run of adjacent nodes that unstuck first (two spots may nucleate at once), grown
  // through neighbours whose fits are too fast, for those unstuck too nearly together to have a front.
  double first_time = std::numeric_limits<double>::infinity();
  for (double time : first_unstick_time) {
    if (!std::isnan(time)) first_time = std::min(first_time, time);
  }
  std::vector<char> in_patch(n, 0);
  for (int node = 0; node < n; ++node) in_patch[node] = first_unstick_time[node] == first_time;
  for (int node = 1; node < n; ++node) in_patch[node] |= in_patch[node - 1] && too_fast(node);
  for (int node = n - 2; node >= 0; --node) in_patch[node] |= in_patch[node + 1] && too_fast(node);
  // patches_before[i]: patch nodes among nodes [0, i). A fit's window [node − behind, node + ahead]
  // (frontFitWindow) mixes a patch's times into its slope when it holds a patch node.
  std::vector<int> patches_before(n + 1, 0);
  for (int node = 0; node < n; ++node) patches_before[node + 1] = patches_before[node] + in_patch[node];
  const FitWindow window = frontFitWindow(fit_nodes);
  auto near_patch = [&](int node) {
    const int low = std::max(node - window.behind, 0), high = std::min(node + window.ahead, n - 1);
    return patches_before[high + 1] > patches_before[low];
  };
  std::vector<double> running;
  for (int node = 0; node < n; ++node) {
    if (std::isnan(front_speed[node])) continue;
    if (near_patch(node) || too_fast(node)) {
      ++summary.left_out;
    } else {
      running.push_back(front_speed[node]);
    }
  }
  if (running.empty()) {
    summary.median = kNaN;
    return summary;
  }
  std::sort(running.begin(), running.end());
  const std::size_t middle = running.size() / 2;
  summary.median = running.size() % 2 ? running[middle] : 0.5 * (running[middle - 1] + running[middle]);
  return summary;
}

void ContactDuringEvent::start(std::size_t nodes) {
  touched_.assign(nodes, 0);
  count_ = 0;
}

void measureExtent(SlipEvent& event, const std::vector<double>& positions, double slider_length,
                   std::size_t nodes_in_contact) {
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
  std::size_t slipped = 0;
  for (std::size_t node = 0; node < positions.size(); ++node) {
    if (std::isnan(event.first_unstick_time[node])) continue;
    ++slipped;
    x_min = std::min(x_min, positions[node]);
    x_max = std::max(x_max, positions[node]);
  }
  event.slip_min_x = x_min;
  event.slip_max_x = x_max;
  event.global = slipped > 0 && slipped == nodes_in_contact;
  if (slipped == 0) {
    event.rupture_length = 0.0;
  } else if (positions.size() == 1) {
    event.rupture_length = slider_length;
  } else {
    event.rupture_length = x_max - x_min;
  }
}

void measureFronts(SlipEvent& event, const std::vector<double>& positions, int fit_nodes, double longitudinal_speed) {
  event.front_speed = frontSpeeds(positions, event.first_unstick_time, fit_nodes);
  const FrontSpeedSummary front =
      summarizeFrontSpeeds(event.front_speed, event.first_unstick_time, fit_nodes, longitudinal_speed);
  event.median_front_speed = front.median;
  event.front_fits_left_out = front.left_out;
}

}  // namespace friction
