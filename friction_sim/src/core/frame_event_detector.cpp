#include "friction_sim/frame_event_detector.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace friction {

namespace {
bool anySliding(const InterfaceFrame& frame) {
  return std::any_of(frame.state.begin(), frame.state.end(),
                     [](std::uint8_t state) { return state == static_cast<std::uint8_t>(ContactState::Sliding); });
}
}  // namespace

FrameEventDetector::FrameEventDetector(double slider_length, int front_fit_nodes)
    : slider_length_(slider_length), front_fit_nodes_(front_fit_nodes) {}

void FrameEventDetector::reset() {
  next_index_ = 0;
  load_cells_.clear();
  last_stuck_frame_.reset();
  in_event_ = false;
}

void FrameEventDetector::addLoadCells(const LoadCellReading& reading) {
  load_cells_.push_back(reading);
  // Older samples than the last all-stuck frame can no longer be an onset.
  const double horizon = last_stuck_frame_ ? last_stuck_frame_->time : -std::numeric_limits<double>::infinity();
  while (load_cells_.size() > 2 && load_cells_[1].time <= horizon) load_cells_.pop_front();
}

std::optional<SlipEvent> FrameEventDetector::addFrame(const InterfaceFrame& frame) {
  const std::size_t n = frame.position.size();
  const bool sliding = anySliding(frame);
  if (!in_event_) {
    if (!sliding || !last_stuck_frame_ || last_stuck_frame_->position.size() != n) {
      if (!sliding) last_stuck_frame_ = frame;
      return std::nullopt;
    }
    in_event_ = true;
    current_ = SlipEvent{};
    current_.index = next_index_++;
    current_.onset_time = frame.time;
    current_.first_unstick_time.assign(n, std::numeric_limits<double>::quiet_NaN());
    double sum = 0.0;
    int count = 0;
    for (std::size_t node = 0; node < n; ++node) {
      if (frame.state[node] != static_cast<std::uint8_t>(ContactState::Sliding)) continue;
      sum += frame.position[node];
      ++count;
    }
    current_.nucleation_position = sum / count;
    // The load cells at the onset: the last sample taken at or before the onset frame.
    for (const LoadCellReading& reading : load_cells_) {
      if (reading.time > frame.time) break;
      current_.onset_shear_force = reading.shear_force;
      current_.onset_normal_force = reading.normal_force;
    }
  }
  for (std::size_t node = 0; node < n; ++node) {
    if (frame.state[node] == static_cast<std::uint8_t>(ContactState::Sliding) &&
        std::isnan(current_.first_unstick_time[node])) {
      current_.first_unstick_time[node] = frame.time;
    }
  }
  if (sliding) return std::nullopt;

  in_event_ = false;
  SlipEvent event = std::move(current_);
  event.end_time = frame.time;
  for (const LoadCellReading& reading : load_cells_) {
    if (reading.time > frame.time) break;
    event.end_shear_force = reading.shear_force;
  }
  event.node_slip.resize(n);
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
  std::size_t slipped = 0;
  for (std::size_t node = 0; node < n; ++node) {
    event.node_slip[node] = frame.slip[node] - last_stuck_frame_->slip[node];
    if (event.node_slip[node] == 0.0) continue;
    ++slipped;
    x_min = std::min(x_min, frame.position[node]);
    x_max = std::max(x_max, frame.position[node]);
  }
  event.slip_min_x = x_min;
  event.slip_max_x = x_max;
  event.rupture_length = slipped ? x_max - x_min : 0.0;
  event.global = slipped == n;
  event.front_speed = frontSpeeds(frame.position, event.first_unstick_time, front_fit_nodes_);
  last_stuck_frame_ = frame;
  return event;
}

}  // namespace friction
