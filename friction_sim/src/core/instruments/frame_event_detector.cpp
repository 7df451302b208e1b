#include "friction_sim/instruments/frame_event_detector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

namespace friction {

FrameEventDetector::FrameEventDetector(int front_fit_nodes, double longitudinal_speed, double slider_length,
                                       SlipCriterion criterion)
    : front_fit_nodes_(front_fit_nodes),
      longitudinal_speed_(longitudinal_speed),
      given_length_(slider_length),
      criterion_(criterion) {}

void FrameEventDetector::reset() {
  next_index_ = 0;
  load_cells_.clear();
  last_stuck_frame_.reset();
  quiet_frame_.reset();
  in_event_ = false;
  seen_global_ = false;
  ended_.clear();
  last_frame_time_ = -std::numeric_limits<double>::infinity();
}

void FrameEventDetector::addLoadCells(const LoadCellReading& reading) { load_cells_.push_back(reading); }

std::vector<SlipEvent> FrameEventDetector::takeCompletedEvents(bool no_more_readings) {
  std::vector<SlipEvent> ready;
  const double latest = no_more_readings      ? std::numeric_limits<double>::infinity()
                        : load_cells_.empty() ? -std::numeric_limits<double>::infinity()
                                              : load_cells_.back().time;
  while (!ended_.empty() && ended_.front().end_time <= latest) {
    SlipEvent event = std::move(ended_.front());
    ended_.pop_front();
    addLoadCellsTo(event);
    ready.push_back(std::move(event));
  }
  // Keep the samples from the last one before any onset still to be resolved: those of ended and
  // current events, and of an event starting after the last all-stuck frame.
  // The topics travel separately: load cells may run ahead of the frames, so never beyond the last frame.
  double horizon = std::min(latest, last_frame_time_);
  if (last_stuck_frame_) horizon = std::min(horizon, last_stuck_frame_->time);
  if (in_event_) horizon = std::min(horizon, current_.onset_time);
  if (!ended_.empty()) horizon = std::min(horizon, ended_.front().onset_time);
  while (load_cells_.size() > 1 && load_cells_[1].time <= horizon) load_cells_.pop_front();
  return ready;
}

void FrameEventDetector::addLoadCellsTo(SlipEvent& event) const {
  // The last samples taken at or before the onset and the end, and the forces' time averages
  // (trapezoids) over the samples from the first of those to the second.
  const LoadCellReading* previous = nullptr;
  double shear_impulse = 0.0, normal_impulse = 0.0, span = 0.0;
  // The peak F_X is watched until the whole interface has slipped (SlipEvent::peak_shear_force).
  // The nodes lifted throughout have no first-unstick time (NaN), which fmax passes over.
  const double peak_until = event.global
                                ? std::accumulate(event.first_unstick_time.begin(), event.first_unstick_time.end(),
                                                  -std::numeric_limits<double>::infinity(),
                                                  [](double a, double b) { return std::fmax(a, b); })
                                : event.end_time;
  for (const LoadCellReading& reading : load_cells_) {
    if (reading.time <= event.onset_time) {
      event.onset_shear_force = event.peak_shear_force = reading.shear_force;
      event.onset_normal_force = reading.normal_force;
      previous = &reading;
    } else if (reading.time <= event.end_time && previous) {
      if (reading.time <= peak_until && std::abs(reading.shear_force) > std::abs(event.peak_shear_force)) {
        event.peak_shear_force = reading.shear_force;
      }
      const double interval = reading.time - previous->time;
      shear_impulse += 0.5 * (previous->shear_force + reading.shear_force) * interval;
      normal_impulse += 0.5 * (previous->normal_force + reading.normal_force) * interval;
      span += interval;
      previous = &reading;
    }
    if (reading.time <= event.end_time) event.end_shear_force = reading.shear_force;
  }
  event.mean_shear_force = span > 0.0 ? shear_impulse / span : event.onset_shear_force;
  event.mean_normal_force = span > 0.0 ? normal_impulse / span : event.onset_normal_force;
}

std::string FrameEventDetector::addFrame(const InterfaceFrame& frame) {
  const std::size_t n = frame.position.size();
  // Frames come from outside (a topic, a bag): the per-node arrays index one another.
  const bool consistent = frame.state.size() == n && frame.slip.size() == n &&
                          (frame.slip_velocity.empty() || frame.slip_velocity.size() == n);
  if (!consistent || (in_event_ && n != current_.peak_slip_velocity.size())) {
    std::ostringstream reason;
    reason << "the frame at t = " << frame.time << " s is left out: ";
    if (!consistent) {
      reason << "its arrays differ in length (" << n << " positions, " << frame.state.size() << " states, "
             << frame.slip.size() << " slips, " << frame.slip_velocity.size() << " slip velocities)";
    } else {
      reason << "it has " << n << " nodes, the event under way " << current_.peak_slip_velocity.size();
    }
    return reason.str();
  }
  last_frame_time_ = frame.time;
  if (n > 0) frames_length_ = frame.position.back();
  std::vector<char> slipping(n);
  std::vector<double> sliding_speed(n, 0.0);  // m/s, |v| of the sliding nodes
  for (std::size_t node = 0; node < n; ++node) {
    const auto state = static_cast<ContactState>(frame.state[node]);
    const double velocity = node < frame.slip_velocity.size() ? frame.slip_velocity[node] : 0.0;
    slipping[node] = criterion_.slipping(state, velocity);
    if (state == ContactState::Sliding) sliding_speed[node] = std::abs(velocity);
  }
  const bool any_slipping = std::find(slipping.begin(), slipping.end(), 1) != slipping.end();
  if (!in_event_) {
    if (!any_slipping || !last_stuck_frame_ || last_stuck_frame_->position.size() != n) {
      if (!any_slipping) last_stuck_frame_ = frame;
      return {};
    }
    in_event_ = true;
    current_ = SlipEvent{};
    current_.index = next_index_++;
    current_.onset_time = frame.time;
    current_.first_unstick_time.assign(n, std::numeric_limits<double>::quiet_NaN());
    current_.last_slip_time.assign(n, std::numeric_limits<double>::quiet_NaN());
    current_.peak_slip_velocity.assign(n, 0.0);
    in_contact_.start(n);
    double sum = 0.0;
    int count = 0;
    for (std::size_t node = 0; node < n; ++node) {
      if (!slipping[node]) continue;
      sum += frame.position[node];
      ++count;
    }
    current_.nucleation_position = sum / count;
  }
  for (std::size_t node = 0; node < n; ++node) {
    if (frame.state[node] != static_cast<std::uint8_t>(ContactState::Detached)) in_contact_.touch(node);
    current_.peak_slip_velocity[node] = std::max(current_.peak_slip_velocity[node], sliding_speed[node]);
    if (!slipping[node]) continue;
    if (std::isnan(current_.first_unstick_time[node])) current_.first_unstick_time[node] = frame.time;
    current_.last_slip_time[node] = frame.time;
  }
  if (any_slipping) {
    quiet_frame_.reset();
    return {};
  }
  if (!quiet_frame_) quiet_frame_ = frame;
  if (frame.time - quiet_frame_->time < criterion_.quiet_time) return {};

  in_event_ = false;
  SlipEvent event = std::move(current_);
  const InterfaceFrame& end = *quiet_frame_;
  event.end_time = end.time;
  event.node_slip.resize(n);
  for (std::size_t node = 0; node < n; ++node) event.node_slip[node] = end.slip[node] - last_stuck_frame_->slip[node];
  // The slipped nodes are those seen slipping, not merely moved: with an interfacial stiffness stuck
  // nodes move elastically, and detached nodes move freely.
  measureExtent(event, frame.position, sliderLength(), in_contact_.count());
  measureFronts(event, frame.position, front_fit_nodes_, longitudinal_speed_);
  event.kind = classifySlipEvent(event, seen_global_);
  seen_global_ = seen_global_ || event.global;
  last_stuck_frame_ = frame;
  quiet_frame_.reset();
  ended_.push_back(std::move(event));
  return {};
}

}  // namespace friction
